// vmhaptics hw list
// vmhaptics hw probe [--device D] [--seconds s]
// vmhaptics hw record [--device D] [--duration s] [--out DIR]
// vmhaptics hw motor-test [--device D] --motor 1|2|3 --torque-mNm x --ms t
//                         [--out DIR]
// (hw run: cli/hw_run.cc; hw calibrate: cli/hw_calibrate.cc)
//
// Each prints one JSON object on stdout. Exit codes: 0 done; 2 bad usage or
// a device that cannot be opened (nothing written); 1 the device stopped
// answering (trace kept, zero torque sent); 130 / 143 SIGINT / SIGTERM
// (trace kept, zero torque sent).
#include "cli/hw.h"

#include <cmath>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/hw_common.h"
#include "cli/hw_usb.h"
#include "controller/device_frame.h"

namespace vmh::cli {
namespace {

struct RecordOptions {
  HwCommon common;
  double duration_s = 5.0;
  double seconds = 1.0;  // probe
  std::string out;
  // motor-test
  int motor = 0;
  double torque_mNm = std::nan("");
  double ms = 0.0;
};

Json joints_json(const Joints& q) { return to_json_vector(q); }

// the last good reading of a session, if any
const HwSample* last_reading(const SessionResult& r) {
  for (auto it = r.samples.rbegin(); it != r.samples.rend(); ++it) {
    if (it->state.has(kStateJoints)) return &*it;
  }
  return nullptr;
}

void probe(const RecordOptions& o) {
  check_seconds("hw probe: --seconds", o.seconds, 0.0, 3600.0);
  // the USB Touch: its descriptors only, no servo backend (cli/hw_usb.cc)
  const DeviceSpec spec = parse_device_spec(o.common.device);
  if (spec.backend == "usb") return usb_probe(spec.argument);
  OpenedDevice dev = open_hw_device(o.common, "tour");
  SessionOptions so = session_options(o.common, "probe");
  so.mode = HwMode::kRecord;
  so.duration_s = o.seconds;
  so.keep_samples = true;
  so.progress = false;
  const SessionResult r = run_session(&dev, so);
  Json out{{"device", identity_json(dev.backend->identity())},
           {"calibration",
            Json{{"state", calibration_state_name(dev.backend->calibration_state())},
                 {"source", dev.calibration_source}}}};
  const double rate = r.duration_s > 0.0 ? static_cast<double>(r.ticks - 1) / r.duration_s : 0.0;
  out["rate_Hz"] = rate;
  if (const HwSample* s = last_reading(r)) {
    out["q_device_rad"] = joints_json(s->state.q_device_rad);
    out["q_dh_rad"] = joints_json(device_to_dh_joints(s->state.q_device_rad));
    out["buttons"] = s->state.buttons;
    out["docked"] = s->state.docked;
    Json fields = Json::array();
    const char* names[] = {"joints", "buttons", "inkwell", "timestamp",
                           "transform", "velocity", "jacobian", "encoders",
                           "gimbal_pots", "safety_switch"};
    for (int i = 0; i < 10; ++i) {
      if (s->state.present & (1u << i)) fields.push_back(names[i]);
    }
    out["reports"] = fields;
    if (s->state.has(kStateEncoders)) {
      out["encoder_counts"] = Json(s->state.encoder_counts);
    }
    if (s->state.has(kStatePots)) out["gimbal_pots"] = Json(s->state.gimbal_pots);
  } else {
    out["q_device_rad"] = nullptr;
  }
  out["session"] = session_json(r);
  std::cout << dump_readable(out) << '\n';
  raise_if_cut_short(r, "probe");
  if (r.ticks < 2 || last_reading(r) == nullptr) {
    throw std::runtime_error("hw probe: no reading from the device in " +
                             std::to_string(o.seconds) + " s");
  }
}

void record(const RecordOptions& o) {
  // a day at most: the recording streams to disk, one row a tick
  check_seconds("hw record: --duration", o.duration_s, 0.0, 86400.0);
  OpenedDevice dev = open_hw_device(o.common, "tour");
  SessionOptions so = session_options(o.common, "record");
  so.mode = HwMode::kRecord;
  so.duration_s = o.duration_s;
  so.out_dir = o.out;
  const SessionResult r = run_session(&dev, so);
  const Json meta = meta_json(dev, r, "record", Json::object());
  write_meta(o.out, meta);
  Json out{{"device", identity_json(dev.backend->identity())},
           {"session", session_json(r)}};
  if (!o.out.empty()) out["outputs"] = {r.trace_path, o.out + "/meta.json"};
  std::cout << dump_readable(out) << '\n';
  raise_if_cut_short(r, "record");
}

void motor_test(const RecordOptions& o) {
  if (o.motor < 1 || o.motor > 3) {
    throw UsageError("hw motor-test: --motor must be 1, 2 or 3");
  }
  if (!std::isfinite(o.torque_mNm)) {
    throw UsageError("hw motor-test: --torque-mNm is required (a number)");
  }
  if (!(o.ms > 0.0) || o.ms > 2000.0) {
    throw UsageError("hw motor-test: --ms must be in (0, 2000]");
  }
  OpenedDevice dev = open_hw_device(o.common, "none");
  SessionOptions so = session_options(o.common, "motor-test");
  so.mode = HwMode::kMotorTest;
  so.motor = o.motor;
  so.torque_Nm = 1e-3 * o.torque_mNm;
  so.pulse_s = 1e-3 * o.ms;
  // the ramp would hold back a short pulse: let it finish before it starts
  so.pulse_start_s = so.safety.ramp_s + 0.1;
  so.duration_s = so.pulse_start_s + so.pulse_s + 0.5;
  so.out_dir = o.out;
  so.keep_samples = true;
  const SessionResult r = run_session(&dev, so);

  // the response of the pulsed joint: its excursion over the pulse and
  // the torque that reached the motor
  const int j = o.motor - 1;
  double q0 = std::nan(""), q_end = std::nan(""), peak_sent = 0.0;
  for (const HwSample& s : r.samples) {
    if (!s.state.has(kStateJoints)) continue;
    const double q = s.state.q_device_rad[j];
    if (s.t_s < so.pulse_start_s) q0 = q;
    if (s.t_s <= so.pulse_start_s + so.pulse_s) q_end = q;
    if (std::abs(s.tau_sent_Nm[j]) > std::abs(peak_sent)) peak_sent = s.tau_sent_Nm[j];
  }
  const double dq = q_end - q0;
  Json out{{"device", identity_json(dev.backend->identity())},
           {"motor", o.motor},
           {"torque_asked_mNm", o.torque_mNm},
           {"torque_sent_peak_mNm", 1e3 * peak_sent},
           {"pulse_ms", o.ms},
           {"joint_start_rad", q0},
           {"joint_end_of_pulse_rad", q_end},
           {"joint_excursion_rad", dq},
           {"moved_with_torque_sign",
            std::isfinite(dq) && dq * o.torque_mNm > 0.0},
           {"session", session_json(r)}};
  write_meta(o.out, meta_json(dev, r, "motor-test", out));
  std::cout << dump_readable(out) << '\n';
  raise_if_cut_short(r, "motor-test");
}

}  // namespace

void register_hw(CLI::App* app) {
  CLI::App* hw = app->add_subcommand(
      "hw",
      "a haptic device, real or emulated, through the same servo_tick and "
      "safety layer: list, probe, record, run, calibrate, motor-test; "
      "capture (USB Touch traffic), decode and encode (FireWire packets) "
      "(docs/hardware.md)");
  hw->require_subcommand(1);

  hw->add_subcommand("list",
                     "every device backend, what it found, or why not")
      ->callback([]() { std::cout << dump_readable(list_backends()) << '\n'; });

  auto po = std::make_shared<RecordOptions>();
  CLI::App* p = hw->add_subcommand(
      "probe", "identification, calibration state and a second of readings");
  add_hw_common(p, &po->common);
  p->add_option("--seconds", po->seconds, "how long to read, > 0 and <= 3600 (default 1)");
  p->callback([po]() { probe(*po); });

  auto ro = std::make_shared<RecordOptions>();
  CLI::App* r = hw->add_subcommand(
      "record", "record the device's readings (zero force) to DIR/trace.csv");
  add_hw_common(r, &ro->common);
  r->add_option("--duration", ro->duration_s, "seconds, > 0 and <= 86400 (default 5)");
  r->add_option("--out", ro->out, "write DIR/trace.csv and DIR/meta.json");
  r->callback([ro]() { record(*ro); });

  auto mo = std::make_shared<RecordOptions>();
  CLI::App* m = hw->add_subcommand(
      "motor-test",
      "one short torque pulse on one motor, every safety limit on, the "
      "response recorded");
  add_hw_common(m, &mo->common);
  m->add_option("--motor", mo->motor, "1, 2 or 3 (t1..t3)")->required();
  m->add_option("--torque-mNm", mo->torque_mNm, "pulse torque, mN m")->required();
  m->add_option("--ms", mo->ms, "pulse length, ms (at most 2000)")->required();
  m->add_option("--out", mo->out, "write DIR/trace.csv and DIR/meta.json");
  m->callback([mo]() { motor_test(*mo); });

  register_hw_run(hw);
  register_hw_calibrate(hw);
  register_hw_packet(hw);
  register_hw_capture(hw);
}

}  // namespace vmh::cli
