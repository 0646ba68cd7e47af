#include "runtime/calibrate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "controller/device_frame.h"
#include "controller/omni_params.h"
#include "runtime/meta.h"

namespace vmh::runtime {
namespace {

// The gimbal joints' ends (t4, t5, t6), device convention, rad
using GimbalRanges = std::array<std::pair<double, double>, 3>;
GimbalRanges gimbal_ranges() {
  Joints lo, hi;
  device_joint_ranges(OmniParams(), &lo, &hi);
  return {std::make_pair(lo[3], hi[3]), std::make_pair(lo[4], hi[4]),
          std::make_pair(lo[5], hi[5])};
}

Json driver_calibration(OpenedDevice* dev) {
  const CalibrationState before = dev->backend->calibration_state();
  const CalibrationState after = dev->backend->update_calibration();
  Json out{{"device", identity_json(dev->backend->identity())},
           {"method", "the device's own routine (" +
                          dev->backend->identity().backend + ")"},
           {"state_before", calibration_state_name(before)},
           {"state_after", calibration_state_name(after)},
           {"stored", nullptr}};
  if (after != CalibrationState::kOk) {
    throw CalibrationError(
        std::string("the driver reports ") + calibration_state_name(after) +
        " (put the stylus in the inkwell, or follow the vendor's "
        "calibration tool)");
  }
  return out;
}

// What the two phases saw, gathered tick by tick (nothing else is kept).
struct Gathered {
  std::array<double, 3> sum{};
  std::array<std::int32_t, 3> dock_lo{}, dock_hi{};
  long docked = 0;
  std::array<int, 3> lo{}, hi{};
  Gathered() {
    lo.fill(std::numeric_limits<int>::max());
    hi.fill(std::numeric_limits<int>::min());
    dock_lo.fill(std::numeric_limits<std::int32_t>::max());
    dock_hi.fill(std::numeric_limits<std::int32_t>::min());
  }

  // one tick: its encoder counts if docked in the dock phase's last
  // second (the phase ends at dock_s), its pot codes in the sweep phase
  void add(const TickRecord& s, double dock_s) {
    if (s.t_s >= dock_s - 1.0 && s.t_s < dock_s &&
        s.state.has(kStateEncoders) && s.state.docked) {
      for (std::size_t i = 0; i < 3; ++i) {
        sum[i] += s.state.encoder_counts[i];
        dock_lo[i] = std::min(dock_lo[i], s.state.encoder_counts[i]);
        dock_hi[i] = std::max(dock_hi[i], s.state.encoder_counts[i]);
      }
      ++docked;
    }
    if (s.t_s >= dock_s && s.state.has(kStatePots)) {
      for (std::size_t j = 0; j < 3; ++j) {
        lo[j] = std::min(lo[j], static_cast<int>(s.state.gimbal_pots[j]));
        hi[j] = std::max(hi[j], static_cast<int>(s.state.gimbal_pots[j]));
      }
    }
  }
};

// The session of the two phases, the dock and then the sweep, each
// prompted on stderr and played by a simulated hand where there is one;
// what they saw into *g
SessionResult run_phases(OpenedDevice* dev, const CalibrateOptions& o,
                         Gathered* g) {
  SessionOptions so;
  so.verb = o.verb;
  so.chain.mode = ChainMode::kRecord;
  so.servo = o.servo;
  so.chain.safety_params.servo_period_s = o.servo.period_s;
  so.duration_s = o.dock_s + o.sweep_s;
  so.progress = o.progress;
  so.on_record = [&](const TickRecord& s) { g->add(s, o.dock_s); };
  bool sweeping = false;
  std::fprintf(stderr, "%s: put the stylus in the inkwell (%.0f s)\n",
               o.verb.c_str(), o.dock_s);
  if (dev->hand != nullptr) dev->hand->set_hand_program("dock");
  so.on_poll = [&](double t_s) {
    if (!sweeping && t_s >= o.dock_s) {
      sweeping = true;
      std::fprintf(stderr,
                   "%s: turn each gimbal joint (t4, t5, t6) to both ends of "
                   "its range (%.0f s)\n", o.verb.c_str(), o.sweep_s);
      if (dev->hand != nullptr) dev->hand->set_hand_program("gimbal_sweep");
    }
  };
  return run_session(dev, so);
}

// 1. inkwell: the mean of the counts over the last second of the dock
// phase, docked; refused where the stylus was docked for under 0.1 s of it
// or an encoder moved
hw::EncoderCounts docked_counts(const Gathered& g, double period_s) {
  const long need = std::lround(0.1 / period_s);
  if (g.docked < need) {
    throw CalibrationError(
        "the stylus was in the inkwell for only " + std::to_string(g.docked) +
        " ticks of the dock phase's last second (need " + std::to_string(need) +
        "): dock it and run again, or give a longer --dock-s; nothing stored");
  }
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const long spread = static_cast<long>(g.dock_hi[k]) - g.dock_lo[k];
    if (spread > kMaxDockSpreadCounts) {
      throw CalibrationError(
          "t" + std::to_string(i + 1) + "'s encoder moved by " +
          std::to_string(spread) + " counts while docked (at most " +
          std::to_string(kMaxDockSpreadCounts) +
          "): let the stylus rest in the inkwell and run again; nothing stored");
    }
  }
  hw::EncoderCounts mean{};
  for (std::size_t i = 0; i < 3; ++i) {
    mean[i] = static_cast<std::int32_t>(
        std::lround(g.sum[i] / static_cast<double>(g.docked)));
  }
  return mean;
}

// 2. gimbal: the extreme codes of the sweep phase are the range's ends;
// each pot's two-point fit into *cal (refused where a pot was not read or
// swept over too few codes), and what each sweep covered
Json fit_gimbal(const Gathered& g, const GimbalRanges& ranges,
                hw::OmniCalibration* cal) {
  Json pots = Json::array();
  for (int j = 0; j < 3; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const std::string joint = "t" + std::to_string(j + 4);
    if (g.lo[k] > g.hi[k]) {
      throw CalibrationError("no potentiometer reading of " + joint +
                             " in the sweep phase; nothing stored");
    }
    const int span = g.hi[k] - g.lo[k];
    if (span < kMinSweepCodes) {
      throw CalibrationError(
          "the sweep of " + joint + " covered codes " + std::to_string(g.lo[k]) +
          ".." + std::to_string(g.hi[k]) + " (" + std::to_string(span) +
          " codes, need at least " + std::to_string(kMinSweepCodes) +
          "): turn " + joint +
          " fully to both ends of its range and run again, or give a longer "
          "--sweep-s; nothing stored");
    }
    // the pot's direction is a property of the design, not of the unit:
    // keep the sign the device's nominal calibration has
    const bool rising = cal->pot_gain_rad[k] >= 0.0;
    const double r_lo = rising ? g.lo[k] : g.hi[k];
    const double r_hi = rising ? g.hi[k] : g.lo[k];
    const hw::PotFit f = hw::fit_pot_two_point(r_lo, ranges[k].first, r_hi,
                                               ranges[k].second, j + 4);
    cal->pot_gain_rad[k] = f.gain_rad;
    cal->pot_offset_rad[k] = f.offset_rad;
    pots.push_back(Json{{"joint", joint},
                        {"code_min", g.lo[k]},
                        {"code_max", g.hi[k]},
                        {"range_rad", {ranges[k].first, ranges[k].second}}});
  }
  return pots;
}

// How far the fit is from a simulated device's truth: each encoder
// offset's error, then the largest angle error of each pot over its
// joint's range
Json error_vs_truth(const hw::OmniCalibration& cal,
                    const hw::OmniCalibration& truth,
                    const GimbalRanges& ranges) {
  Json err = Json::array();
  for (std::size_t i = 0; i < 3; ++i) {
    err.push_back(
        std::abs(cal.encoder_offset_rad[i] - truth.encoder_offset_rad[i]));
  }
  for (std::size_t j = 0; j < 3; ++j) {
    double worst = 0.0;
    for (const double th : {ranges[j].first, ranges[j].second}) {
      const double code =
          (th - truth.pot_offset_rad[j]) / truth.pot_gain_rad[j];
      worst = std::max(worst, std::abs(cal.pot_gain_rad[j] * code +
                                       cal.pot_offset_rad[j] - th));
    }
    err.push_back(worst);
  }
  return err;
}

}  // namespace

Json calibrate(OpenedDevice* dev, const CalibrateOptions& o) {
  if (dev->backend->has_driver_calibration()) return driver_calibration(dev);
  if (dev->raw == nullptr) {
    throw CalibrationError(dev->backend->identity().backend +
                           ": reports no raw sensor values to calibrate");
  }
  Gathered g;
  const SessionResult r = run_phases(dev, o, &g);
  raise_if_cut_short(r, o.verb);

  const hw::EncoderCounts mean = docked_counts(g, o.servo.period_s);
  // start from the calibration the device decodes with: its encoder signs,
  // its inkwell pose and its pot gains' signs are kept; the offsets are
  // fitted
  hw::OmniCalibration cal = dev->raw->calibration();
  const Vec3 inkwell(cal.inkwell_t123_rad[0], cal.inkwell_t123_rad[1],
                     cal.inkwell_t123_rad[2]);
  cal.encoder_offset_rad =
      hw::fit_encoder_offsets(mean, inkwell, cal.encoder_sign);
  const GimbalRanges ranges = gimbal_ranges();
  const Json pots = fit_gimbal(g, ranges, &cal);
  check_calibration(cal, "the fit");

  StoredCalibration stored;
  stored.calibration = cal;
  stored.serial = dev->backend->identity().serial;
  stored.backend = dev->backend->identity().backend;
  stored.date_utc = utc_now();
  Json spread = Json::array();
  for (std::size_t i = 0; i < 3; ++i) {
    spread.push_back(static_cast<long>(g.dock_hi[i]) - g.dock_lo[i]);
  }
  stored.details = Json{{"inkwell_pose_rad", {inkwell[0], inkwell[1], inkwell[2]}},
                        {"encoder_sign", cal.encoder_sign},
                        {"docked_ticks", g.docked},
                        {"docked_counts", mean},
                        {"docked_spread_counts", spread},
                        {"gimbal", pots}};
  Json out{{"device", identity_json(dev->backend->identity())},
           {"encoder_offset_rad", cal.encoder_offset_rad},
           {"encoder_sign", cal.encoder_sign},
           {"inkwell_t123_rad", cal.inkwell_t123_rad},
           {"pot_gain_rad", cal.pot_gain_rad},
           {"pot_offset_rad", cal.pot_offset_rad},
           {"details", stored.details},
           {"clock", r.clock}};
  hw::OmniCalibration truth;
  if (dev->raw->factory_calibration(&truth)) {
    // a simulated device knows the truth: how far the fit is from it
    out["error_vs_truth_rad"] = error_vs_truth(cal, truth, ranges);
  }
  out["stored"] = save_calibration(stored);
  return out;
}

}  // namespace vmh::runtime
