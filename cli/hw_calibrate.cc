// vmhaptics hw calibrate [--device D] [--dock-s s] [--sweep-s s]
//
// Joint-angle calibration of a device that reports raw sensor values (the
// emulator, directly or behind the FireWire packets, and the native
// FireWire driver), stored per serial number
// (cli/hw_calibration_store.h) and loaded by the other hw verbs:
//   1. the stylus in the inkwell: the encoder offsets that make the docked
//      counts read as the inkwell pose (hw::fit_encoder_offsets);
//   2. each gimbal joint turned to both ends of its range: a two-point fit
//      of its potentiometer, the extreme codes taken as the range's ends
//      (hw::fit_pot_two_point).
// On the emulator the scripted hand does both (hand programs dock and
// gimbal_sweep); on a device the user does, prompted on stderr. Through
// OpenHaptics the driver keeps its own calibration: calibrate asks it to
// update (hdUpdateCalibration) and reports the state before and after.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>

#include "cli/args.h"
#include "cli/hw.h"
#include "cli/hw_calibration_store.h"
#include "cli/hw_common.h"
#include "controller/device_frame.h"
#include "controller/omni_params.h"
#include "hw/firewire/firewire_omni.h"
#include "hw/openhaptics/openhaptics_backend.h"
#include "sim/emulator.h"

namespace vmh::cli {
namespace {

struct CalibrateOptions {
  HwCommon common;
  double dock_s = 6.0;
  double sweep_s = 10.0;
};

// The gimbal joints' ends, device convention, rad
std::array<std::pair<double, double>, 3> gimbal_ranges() {
  Joints lo, hi;
  device_joint_ranges(OmniParams(), &lo, &hi);
  return {std::make_pair(lo[3], hi[3]), std::make_pair(lo[4], hi[4]),
          std::make_pair(lo[5], hi[5])};
}

void calibrate_openhaptics(OpenedDevice* dev) {
  auto* oh = dynamic_cast<hw::OpenHapticsBackend*>(dev->backend.get());
  const CalibrationState before = dev->backend->calibration_state();
  oh->update_calibration();
  const CalibrationState after = dev->backend->calibration_state();
  Json out{{"device", identity_json(dev->backend->identity())},
           {"method", "the OpenHaptics driver (hdUpdateCalibration)"},
           {"state_before", calibration_state_name(before)},
           {"state_after", calibration_state_name(after)},
           {"stored", nullptr}};
  std::cout << dump_readable(out) << '\n';
  if (after != CalibrationState::kOk) {
    throw std::runtime_error(
        std::string("hw calibrate: the driver reports ") +
        calibration_state_name(after) +
        " (put the stylus in the inkwell, or follow the vendor's "
        "calibration tool)");
  }
}

void calibrate(const CalibrateOptions& o) {
  check_seconds("hw calibrate: --dock-s", o.dock_s, 1.0, 600.0);
  check_seconds("hw calibrate: --sweep-s", o.sweep_s, 1.0, 600.0);
  HwCommon c = o.common;
  c.no_calibration = true;  // fit from the raw readings alone
  OpenedDevice dev = open_hw_device(c, "dock");
  if (dev.backend->identity().backend == "openhaptics") {
    calibrate_openhaptics(&dev);
    return;
  }
  sim::Emulator* emu = dev.emulator;
  SessionOptions so = session_options(c, "calibrate");
  so.mode = HwMode::kRecord;
  so.duration_s = o.dock_s + o.sweep_s;
  so.keep_samples = true;
  bool sweeping = false;
  std::fprintf(stderr, "hw calibrate: put the stylus in the inkwell (%.0f s)\n",
               o.dock_s);
  if (emu != nullptr) emu->set_hand_program(sim::HandProgram::kDock);
  so.on_poll = [&](double t_s) {
    if (!sweeping && t_s >= o.dock_s) {
      sweeping = true;
      std::fprintf(stderr,
                   "hw calibrate: turn each gimbal joint (t4, t5, t6) to both "
                   "ends of its range (%.0f s)\n", o.sweep_s);
      if (emu != nullptr) emu->set_hand_program(sim::HandProgram::kGimbalSweep);
    }
  };
  const SessionResult r = run_session(&dev, so);
  raise_if_cut_short(r, "calibrate");

  // 1. inkwell: the counts over the last second of the dock phase, docked
  std::array<double, 3> sum{};
  long docked = 0;
  for (const HwSample& s : r.samples) {
    if (s.t_s < o.dock_s - 1.0 || s.t_s >= o.dock_s) continue;
    if (!s.state.has(kStateEncoders) || !s.state.docked) continue;
    for (int i = 0; i < 3; ++i) sum[i] += s.state.encoder_counts[i];
    ++docked;
  }
  if (docked < 100) {
    throw std::runtime_error(
        "hw calibrate: the stylus was in the inkwell for only " +
        std::to_string(docked) +
        " ticks of the dock phase's last second (need 100): dock it and "
        "run again, or give a longer --dock-s");
  }
  hw::EncoderCounts mean{};
  for (int i = 0; i < 3; ++i) {
    mean[i] = static_cast<std::int32_t>(std::lround(sum[i] / static_cast<double>(docked)));
  }
  const Vec3 inkwell(sim::kInkwellDevice_rad[0], sim::kInkwellDevice_rad[1],
                     sim::kInkwellDevice_rad[2]);
  // start from the calibration the device decodes with (its pot gains'
  // signs are kept below)
  hw::OmniCalibration cal = dev.firewire != nullptr
                                ? dev.firewire->omni()->calibration()
                                : emu != nullptr ? emu->calibration()
                                                 : hw::OmniCalibration{};
  cal.encoder_offset_rad = hw::fit_encoder_offsets(mean, inkwell);

  // 2. gimbal: the extreme codes of the sweep phase are the range's ends
  std::array<int, 3> lo, hi;
  lo.fill(std::numeric_limits<int>::max());
  hi.fill(std::numeric_limits<int>::min());
  for (const HwSample& s : r.samples) {
    if (s.t_s < o.dock_s || !s.state.has(kStatePots)) continue;
    for (int j = 0; j < 3; ++j) {
      lo[j] = std::min(lo[j], static_cast<int>(s.state.gimbal_pots[j]));
      hi[j] = std::max(hi[j], static_cast<int>(s.state.gimbal_pots[j]));
    }
  }
  const auto ranges = gimbal_ranges();
  Json pots = Json::array();
  for (int j = 0; j < 3; ++j) {
    if (lo[j] > hi[j]) {
      throw std::runtime_error("hw calibrate: no potentiometer reading of t" +
                               std::to_string(j + 4) + " in the sweep phase");
    }
    // the pot's direction is a property of the design, not of the unit:
    // keep the sign the device's nominal calibration has
    const bool rising = cal.pot_gain_rad[j] >= 0.0;
    const double r_lo = rising ? lo[j] : hi[j];
    const double r_hi = rising ? hi[j] : lo[j];
    const hw::PotFit f = hw::fit_pot_two_point(r_lo, ranges[j].first, r_hi,
                                               ranges[j].second, j + 4);
    cal.pot_gain_rad[j] = f.gain_rad;
    cal.pot_offset_rad[j] = f.offset_rad;
    pots.push_back(Json{{"joint", "t" + std::to_string(j + 4)},
                        {"code_min", lo[j]},
                        {"code_max", hi[j]},
                        {"range_rad", {ranges[j].first, ranges[j].second}}});
  }
  cal.validate();

  StoredCalibration stored;
  stored.calibration = cal;
  stored.serial = dev.backend->identity().serial;
  stored.backend = dev.backend->identity().backend;
  stored.date_utc = utc_now();
  stored.details = Json{{"inkwell_pose_rad", {inkwell[0], inkwell[1], inkwell[2]}},
                        {"docked_ticks", docked},
                        {"docked_counts", mean},
                        {"gimbal", pots}};
  Json out{{"device", identity_json(dev.backend->identity())},
           {"encoder_offset_rad", cal.encoder_offset_rad},
           {"pot_gain_rad", cal.pot_gain_rad},
           {"pot_offset_rad", cal.pot_offset_rad},
           {"details", stored.details}};
  if (emu != nullptr) {
    // the emulator knows the truth: how far the fit is from it, as the
    // largest angle error over each joint's range
    const hw::OmniCalibration& truth = emu->factory_calibration();
    Json err = Json::array();
    for (int i = 0; i < 3; ++i) {
      err.push_back(std::abs(cal.encoder_offset_rad[i] - truth.encoder_offset_rad[i]));
    }
    for (int j = 0; j < 3; ++j) {
      double worst = 0.0;
      for (const double th : {ranges[j].first, ranges[j].second}) {
        const double code = (th - truth.pot_offset_rad[j]) / truth.pot_gain_rad[j];
        worst = std::max(worst, std::abs(cal.pot_gain_rad[j] * code +
                                         cal.pot_offset_rad[j] - th));
      }
      err.push_back(worst);
    }
    out["error_vs_truth_rad"] = err;
  }
  out["stored"] = save_calibration(stored);
  std::cout << dump_readable(out) << '\n';
}

}  // namespace

void register_hw_calibrate(CLI::App* hw) {
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = hw->add_subcommand(
      "calibrate",
      "inkwell calibration (encoder offsets) and the gimbal potentiometers' "
      "two-point fit, stored per serial number under "
      "$XDG_CONFIG_HOME/vmhaptics/calibration/");
  add_hw_common(cmd, &o->common);
  cmd->add_option("--dock-s", o->dock_s,
                  "seconds for the inkwell phase, > 1 and <= 600 (default 6)");
  cmd->add_option("--sweep-s", o->sweep_s,
                  "seconds for the gimbal sweep, > 1 and <= 600 (default 10)");
  cmd->callback([o]() { calibrate(*o); });
}

}  // namespace vmh::cli
