#include "cli/hw_session.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "cli/hw_loop.h"
#include "device/stop_signal.h"
#include "device/tick_timer.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;

void put(std::string* s, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g,", v);
  *s += buf;
}
void put_int(std::string* s, long v) {
  *s += std::to_string(v);
  *s += ',';
}
void put_text(std::string* s, const char* t) {
  *s += t;
  *s += ',';
}

// One CSV row, in hw_trace_columns' order.
void format_row(const HwSample& h, HwMode mode, std::uint32_t present,
                int vm_dof, const OmniParams& omni, std::string* s) {
  const bool ok = h.state.has(kStateJoints);
  const double nan = std::nan("");
  put(s, h.t_s);
  put(s, h.period_s);
  const Joints q_dh = device_to_dh_joints(h.state.q_device_rad);
  for (int i = 0; i < 6; ++i) put(s, ok ? q_dh[i] : nan);
  Vec3 p = Vec3::Constant(nan), a = Vec3::Constant(nan);
  if (ok) {
    const OmniPose pose = omni_fk(omni, q_dh);
    p = base_to_device_mm(omni, pose.p_base_m);
    a = base_to_device_vector(pose.R_base.col(2));
  }
  for (int i = 0; i < 3; ++i) put(s, p[i]);
  for (int i = 0; i < 3; ++i) put(s, a[i]);
  if (mode == HwMode::kRun) {
    const ControlOutput& o = h.out;
    for (int i = 0; i < vm_dof; ++i) put(s, i < o.theta_v.size() ? o.theta_v[i] : 0.0);
    for (int i = 0; i < vm_dof; ++i) put(s, i < o.theta_r.size() ? o.theta_r[i] : 0.0);
    for (int i = 0; i < 3; ++i) put(s, o.x_v_mm[i]);
    for (int i = 0; i < 3; ++i) put(s, o.x_r_mm[i]);
    for (int i = 0; i < 6; ++i) put(s, o.e[i]);
    for (int i = 0; i < 6; ++i) put(s, o.f_motion[i]);
    for (int i = 0; i < 3; ++i) put(s, o.force_device_N[i]);
  }
  for (int i = 0; i < 3; ++i) put(s, h.tau_cmd_Nm[i]);
  for (int i = 0; i < 3; ++i) put(s, h.tau_sent_Nm[i]);
  if (h.has_truth) {
    for (int i = 0; i < 3; ++i) put(s, h.truth.motor_torque_Nm[i]);
    for (int i = 0; i < 3; ++i) put(s, h.truth.hand_target.p_mm[i]);
    for (int i = 0; i < 3; ++i) put(s, h.truth.hand_force_N[i]);
    if (mode == HwMode::kRun) put(s, h.truth.d_path_mm);
  }
  if (mode == HwMode::kRun) put_int(s, static_cast<long>(h.out.status));
  put_int(s, static_cast<long>(h.state.buttons));
  put_int(s, h.state.docked ? 1 : 0);
  put_text(s, device_error_name(h.servo.read));
  put_text(s, device_error_name(h.servo.write));
  put_int(s, static_cast<long>(h.safety));
  put_text(s, safety_flags_text(h.safety).c_str());
  put(s, h.ramp_scale);
  if (present & kStateTransform) {
    const bool has = h.state.has(kStateTransform);
    for (int i = 0; i < 3; ++i) put(s, has ? h.state.transform_mm(i, 3) : nan);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) put(s, has ? h.state.transform_mm(r, c) : nan);
    }
  }
  if (present & kStateVelocity) {
    const bool has = h.state.has(kStateVelocity);
    for (int i = 0; i < 3; ++i) put(s, has ? h.state.velocity_mm_s[i] : nan);
  }
  if (present & kStateJacobian) {
    const bool has = h.state.has(kStateJacobian);
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) put(s, has ? h.state.jacobian(r, c) : nan);
    }
  }
  if (present & kStateEncoders) {
    for (int i = 0; i < 3; ++i) put_int(s, h.state.encoder_counts[i]);
  }
  if (present & kStatePots) {
    for (int i = 0; i < 3; ++i) put_int(s, h.state.gimbal_pots[i]);
  }
  s->back() = '\n';
}

std::string join_csv(const std::vector<std::string>& cols) {
  std::string s;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    s += cols[i];
    s += i + 1 < cols.size() ? ',' : '\n';
  }
  return s;
}

}  // namespace

std::string safety_flags_text(SafetyStatus s) {
  if (s == kSafetyOk) return "ok";
  std::string out;
  for (int i = 0; i < kSafetyFlagCount; ++i) {
    const SafetyStatus f = 1u << i;
    if (s & f) {
      if (!out.empty()) out += '|';
      out += safety_flag_name(f);
    }
  }
  return out;
}

std::vector<std::string> hw_trace_columns(HwMode mode, std::uint32_t present,
                                          bool truth, int vm_dof) {
  std::vector<std::string> c = {"t_s", "period_s"};
  const char* xyz[] = {"x", "y", "z"};
  for (int i = 1; i <= 6; ++i) c.push_back("q" + std::to_string(i) + "_rad");
  for (const char* a : xyz) c.push_back(std::string("p_") + a + "_mm");
  for (const char* a : xyz) c.push_back(std::string("a_") + a);
  if (mode == HwMode::kRun) {
    for (const char* v : {"theta_v_", "theta_r_"}) {
      for (int i = 1; i <= vm_dof; ++i) c.push_back(v + std::to_string(i));
    }
    for (const char* v : {"xv_", "xr_"}) {
      for (const char* a : xyz) c.push_back(std::string(v) + a + "_mm");
    }
    for (int i = 1; i <= 6; ++i) {
      c.push_back("e_" + std::to_string(i) + (i <= 3 ? "_mm" : "_rad"));
    }
    for (int i = 1; i <= 6; ++i) {
      c.push_back("f_" + std::to_string(i) + (i <= 3 ? "_N" : "_Nmm"));
    }
    for (const char* a : xyz) c.push_back(std::string("F_") + a + "_N");
  }
  for (int i = 1; i <= 3; ++i) c.push_back("tau_" + std::to_string(i) + "_Nm");
  for (int i = 1; i <= 3; ++i) {
    c.push_back("tau_sent_" + std::to_string(i) + "_Nm");
  }
  if (truth) {
    for (int i = 1; i <= 3; ++i) {
      c.push_back("tau_applied_" + std::to_string(i) + "_Nm");
    }
    for (const char* a : xyz) c.push_back(std::string("hand_") + a + "_mm");
    for (const char* a : xyz) c.push_back(std::string("hand_F_") + a + "_N");
    if (mode == HwMode::kRun) c.push_back("d_path_mm");
  }
  if (mode == HwMode::kRun) c.push_back("status");
  for (const char* n : {"buttons", "docked", "read_error", "write_error",
                        "safety", "safety_flags", "ramp_scale"}) {
    c.push_back(n);
  }
  if (present & kStateTransform) {
    for (const char* a : xyz) c.push_back(std::string("dev_p_") + a + "_mm");
    for (int r = 1; r <= 3; ++r) {
      for (int k = 1; k <= 3; ++k) {
        c.push_back("dev_R_" + std::to_string(r) + std::to_string(k));
      }
    }
  }
  if (present & kStateVelocity) {
    for (const char* a : xyz) c.push_back(std::string("dev_v_") + a + "_mm_s");
  }
  if (present & kStateJacobian) {
    for (int r = 1; r <= 6; ++r) {
      for (int k = 1; k <= 6; ++k) {
        c.push_back("dev_J_" + std::to_string(r) + std::to_string(k));
      }
    }
  }
  if (present & kStateEncoders) {
    for (int i = 1; i <= 3; ++i) c.push_back("enc_" + std::to_string(i));
  }
  if (present & kStatePots) {
    for (int i = 4; i <= 6; ++i) c.push_back("pot_" + std::to_string(i));
  }
  return c;
}

SessionResult run_session(OpenedDevice* dev, const SessionOptions& o) {
  DeviceBackend& backend = *dev->backend;
  const OmniParams omni;
  const int vm_dof =
      o.controller ? Controller(*o.controller).mechanism().dof() : 0;
  HwLoop loop(backend.device(), o, omni, dev->emulator);

  SessionResult r;
  StopSignals signals;
  // started before anything is written: a device that cannot start leaves
  // no file behind (the first ticks wait in the ring meanwhile)
  r.servo_report = backend.start(&loop, o.servo);
  std::ofstream trace;
  if (!o.out_dir.empty()) {
    std::error_code ec;
    fs::create_directories(o.out_dir, ec);
    r.trace_path = (fs::path(o.out_dir) / "trace.csv").string();
    if (!ec) trace.open(r.trace_path, std::ios::out | std::ios::trunc);
    if (ec || !trace) {
      backend.stop();
      throw std::runtime_error(o.verb + ": cannot write " + r.trace_path +
                               (ec ? " (" + ec.message() + ")" : ""));
    }
  }

  bool header = false;
  std::uint32_t present = 0;
  std::string rows;
  HwSample s;
  double comm_lost_since = -1.0;
  double next_progress_s = 1.0;
  bool write_failed = false;
  auto drain = [&]() {
    rows.clear();
    while (loop.ring().pop(&s)) {
      if (!header && s.state.has(kStateJoints)) {
        present = s.state.present;
        header = true;
        if (trace) trace << join_csv(hw_trace_columns(o.mode, present, s.has_truth, vm_dof));
      }
      if (header && trace) format_row(s, o.mode, present, vm_dof, omni, &rows);
      for (int i = 0; i < kSafetyFlagCount; ++i) {
        if (s.safety & (1u << i)) ++r.safety_ticks[safety_flag_name(1u << i)];
      }
      if (s.servo.read != DeviceError::kOk) {
        ++r.read_errors[device_error_name(s.servo.read)];
      }
      if (s.servo.zeroed) ++r.zeroed_ticks;
      if (s.safety & kSafetyCommLost) {
        if (comm_lost_since < 0.0) comm_lost_since = s.t_s;
        if (s.t_s - comm_lost_since >= o.give_up_s && !r.device_gone) {
          r.device_gone = true;
          r.stop_reason = std::string("device_gone: no reading for ") +
                          std::to_string(o.give_up_s) + " s (last error: " +
                          device_error_name(s.servo.read) + ")";
        }
      } else {
        comm_lost_since = -1.0;
      }
      r.duration_s = s.t_s;
      if (o.keep_samples) r.samples.push_back(s);
    }
    if (trace && !rows.empty()) {
      trace << rows;
      trace.flush();
      // a full disk: stop rather than drive the device unrecorded
      if (!trace) write_failed = true;
    }
  };

  while (backend.running() && !signals.requested() && !r.device_gone &&
         !write_failed) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    drain();
    if (o.on_poll) o.on_poll(r.duration_s);
    if (o.progress && r.duration_s >= next_progress_s) {
      const TickStats t = backend.timing();
      std::fprintf(stderr,
                   "%s: %.1f/%.1f s, %ld ticks, %ld overruns, jitter p99 %.0f us\n",
                   o.verb.c_str(), r.duration_s, o.duration_s, t.ticks,
                   t.overruns, 1e6 * t.jitter_p99_s);
      next_progress_s += 1.0;
    }
  }
  backend.stop();  // zero torque at the device
  drain();
  if (signals.requested()) {
    r.signal = signals.signal_number();
    r.stop_reason = std::string("signal ") +
                    (r.signal == SIGINT ? "SIGINT" : r.signal == SIGTERM ? "SIGTERM" : "?");
  } else if (r.stop_reason.empty()) {
    r.stop_reason = r.duration_s >= o.duration_s ? "duration" : "loop_ended";
  }
  if (write_failed) {
    throw std::runtime_error(o.verb + ": writing " + r.trace_path +
                             " failed (disk full?); the device was stopped "
                             "at zero torque");
  }
  r.ticks = loop.ticks();
  r.dropped = loop.ring().dropped();
  r.timing = backend.timing();
  if (trace && !header) {
    // not one good reading: the columns are still written, so the file
    // says what would have been recorded
    trace << join_csv(hw_trace_columns(o.mode, 0, dev->emulator != nullptr, vm_dof));
  }
  return r;
}

}  // namespace vmh::cli
