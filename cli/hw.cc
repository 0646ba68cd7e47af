// vmhaptics hw list
// vmhaptics hw probe [--device D] [--seconds s]
// vmhaptics hw record [--device D] [--duration s] [--out DIR]
// vmhaptics hw motor-test [--device D] --motor 1|2|3 --torque-mNm x --ms t
//                         [--out DIR]
// (hw run: cli/hw_run.cc; hw calibrate: cli/hw_calibrate.cc; hw decode and
// hw encode: cli/hw_packet.cc; hw capture: cli/hw_usb.cc)
//
// Each prints one JSON object on stdout. The sessions are the runtime's
// (runtime/session.h); this file parses, calls and prints. Exit codes: 0
// done; 2 bad usage, an unusable --out, or a device that cannot be opened
// (nothing written); 1 the device stopped answering (trace kept, zero
// torque sent); 130 / 143 SIGINT / SIGTERM (trace kept, zero torque sent;
// record and motor-test catch them from the start: one before the
// session writes nothing, one after it lets the set go in whole).
#include "cli/hw.h"

#include <cmath>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/hw_common.h"
#include "cli/hw_usb.h"
#include "controller/device_frame.h"
#include "device/stop_signal.h"
#include "runtime/stop.h"
#include "runtime/meta.h"

namespace vmh::cli {
namespace {


struct RecordOptions {
  HwCommon common;
  double duration_s = 5.0;
  double seconds = 1.0;  // probe
  std::string out;
  CLI::Option* out_option = nullptr;
  // motor-test
  int motor = 0;
  double torque_mNm = std::nan("");
  double ms = 0.0;

  bool out_given() const { return out_option != nullptr && out_option->count() > 0; }
};

const char* const kFieldNames[] = {"joints",    "buttons",  "inkwell",
                                   "timestamp", "transform", "velocity",
                                   "jacobian",  "encoders", "gimbal_pots",
                                   "safety_switch"};

void probe(const RecordOptions& o) {
  check_seconds("hw probe: --seconds", o.seconds, 0.0, 3600.0);
  std::string argument;
  const runtime::BackendInfo& b = hw_backend(o.common, &argument);
  if (!b.servo) {
    // a backend without a servo loop (the USB Touch): its descriptors
    std::cout << dump_readable(b.probe(argument)) << '\n';
    return;
  }
  runtime::OpenedDevice dev = open_hw_device(o.common, "tour");
  runtime::SessionOptions so = session_options(o.common, "probe");
  so.chain.mode = ChainMode::kRecord;
  so.duration_s = o.seconds;
  so.progress = false;
  const runtime::SessionResult r = runtime::run_session(&dev, so);
  Json out{{"device", runtime::identity_json(dev.backend->identity())},
           {"calibration", runtime::calibration_json(&dev)}};
  const double rate =
      r.duration_s > 0.0 ? static_cast<double>(r.ticks - 1) / r.duration_s : 0.0;
  out["rate_Hz"] = rate;
  const DeviceState& s = r.last_reading;
  if (s.has(kStateJoints)) {
    out["q_device_rad"] = to_json_vector(s.q_device_rad);
    out["q_dh_rad"] = to_json_vector(device_to_dh_joints(s.q_device_rad));
    out["buttons"] = s.buttons;
    out["docked"] = s.docked;
    Json fields = Json::array();
    for (int i = 0; i < 10; ++i) {
      if (s.present & (1u << i)) fields.push_back(kFieldNames[i]);
    }
    out["reports"] = fields;
    if (s.has(kStateEncoders)) out["encoder_counts"] = Json(s.encoder_counts);
    if (s.has(kStatePots)) out["gimbal_pots"] = Json(s.gimbal_pots);
  } else {
    out["q_device_rad"] = nullptr;
  }
  out["session"] = runtime::session_json(r);
  if (dev.meta) {
    // the native FireWire driver's node, start sequence and packet counts
    const Json m = dev.meta();
    if (m.contains("firewire")) out["firewire"] = m.at("firewire");
  }
  std::cout << dump_readable(out) << '\n';
  runtime::raise_if_cut_short(r, "hw probe");
  if (r.ticks < 2 || !s.has(kStateJoints)) {
    throw std::runtime_error("hw probe: no reading from the device in " +
                             std::to_string(o.seconds) + " s");
  }
}

void record(const RecordOptions& o) {
  // a day at most: the recording streams to disk, one row a tick
  check_seconds("hw record: --duration", o.duration_s, 0.0, 86400.0);
  StopSignals signals;  // for the whole verb; the session shares it
  auto set = hw_output_set("record", o.out, o.out_given());
  runtime::throw_if_stopped("hw record", "; nothing written");
  runtime::OpenedDevice dev = open_hw_device(o.common, "tour");
  runtime::SessionOptions so = session_options(o.common, "record");
  so.chain.mode = ChainMode::kRecord;
  so.duration_s = o.duration_s;
  trace_into(set.get(), o.out, &so);
  const runtime::SessionResult r = runtime::run_session(&dev, so);
  Json out{{"device", runtime::identity_json(dev.backend->identity())},
           {"session", runtime::session_json(r)}};
  if (set) {
    set->write("meta.json",
               dump_readable(runtime::meta_json(&dev, r, "record", Json::object())) +
                   "\n");
    set->commit();
    out["outputs"] = {r.trace_path, o.out + "/meta.json"};
  }
  std::cout << dump_readable(out) << '\n';
  runtime::raise_if_cut_short(r, "hw record");
  runtime::throw_if_stopped("hw record", "; after its session");
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
  StopSignals signals;  // for the whole verb; the session shares it
  auto set = hw_output_set("motor-test", o.out, o.out_given());
  runtime::throw_if_stopped("hw motor-test", "; nothing written");
  runtime::OpenedDevice dev = open_hw_device(o.common, "none");
  runtime::SessionOptions so = session_options(o.common, "motor-test");
  so.chain.mode = ChainMode::kMotorTest;
  MotorPulse& pulse = so.chain.pulse;
  pulse.motor = o.motor;
  pulse.torque_Nm = 1e-3 * o.torque_mNm;
  pulse.length_s = 1e-3 * o.ms;
  // the ramp would hold back a short pulse: let it finish before it starts
  pulse.start_s = so.chain.safety_params.ramp_s + 0.1;
  so.duration_s = pulse.start_s + pulse.length_s + 0.5;
  trace_into(set.get(), o.out, &so);
  // the response of the pulsed joint: its excursion over the pulse and the
  // torque that reached the motor
  const int j = o.motor - 1;
  double q0 = std::nan(""), q_end = std::nan(""), peak_sent = 0.0;
  so.on_record = [&](const TickRecord& s) {
    if (s.servo.read != DeviceError::kOk) return;
    const double q = s.state.q_device_rad[j];
    if (s.t_s < pulse.start_s) q0 = q;
    if (s.t_s <= pulse.start_s + pulse.length_s) q_end = q;
    if (std::abs(s.tau_sent_Nm[j]) > std::abs(peak_sent)) peak_sent = s.tau_sent_Nm[j];
  };
  const runtime::SessionResult r = runtime::run_session(&dev, so);
  const double dq = q_end - q0;
  Json out{{"device", runtime::identity_json(dev.backend->identity())},
           {"motor", o.motor},
           {"torque_asked_mNm", o.torque_mNm},
           {"torque_sent_peak_mNm", 1e3 * peak_sent},
           {"pulse_ms", o.ms},
           {"joint_start_rad", q0},
           {"joint_end_of_pulse_rad", q_end},
           {"joint_excursion_rad", dq},
           {"moved_with_torque_sign", std::isfinite(dq) && dq * o.torque_mNm > 0.0},
           {"session", runtime::session_json(r)}};
  if (set) {
    set->write("meta.json",
               dump_readable(runtime::meta_json(&dev, r, "motor-test", out)) + "\n");
    set->commit();
  }
  std::cout << dump_readable(out) << '\n';
  runtime::raise_if_cut_short(r, "hw motor-test");
  runtime::throw_if_stopped("hw motor-test", "; after its session");
}

}  // namespace

void register_hw(CLI::App* app) {
  CLI::App* hw = app->add_subcommand(
      "hw",
      "a haptic device, real or emulated, through the same servo chain and "
      "safety layer: list, probe, record, run, calibrate, motor-test; "
      "capture (USB Touch traffic), decode and encode (FireWire packets) "
      "(docs/hardware.md)");
  hw->require_subcommand(1);

  hw->add_subcommand("list",
                     "every device backend, what it found, or why not")
      ->callback([]() {
        std::cout << dump_readable(runtime::BackendRegistry::global().list())
                  << '\n';
      });

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
  ro->out_option = r->add_option(
      "--out", ro->out,
      "write DIR/trace.csv and DIR/meta.json, together (a set replaced whole)");
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
  mo->out_option = m->add_option(
      "--out", mo->out,
      "write DIR/trace.csv and DIR/meta.json, together (a set replaced whole)");
  m->callback([mo]() { motor_test(*mo); });

  register_hw_run(hw);
  register_hw_calibrate(hw);
  register_hw_packet(hw);
  register_hw_capture(hw);
}

}  // namespace vmh::cli
