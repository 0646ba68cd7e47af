#include "runtime/session.h"

#include <csignal>
#include <cstdio>
#include <deque>
#include <memory>

#include "device/stop_signal.h"
#include "runtime/session_loop.h"

namespace vmh::runtime {
namespace {

// the session's thread waits this much loop time between drains
constexpr double kPollS = 0.02;
// records held back until the first good reading says which columns the
// device reports: at most this much loop time, then the header is written
// with the joints alone
constexpr double kHoldForLayoutS = 1.0;

// The recorder: the trace's layout (from the first good reading), the
// writer, and the session's counts.
class Recorder {
 public:
  Recorder(const SessionOptions& o, const OpenedDevice& dev, SessionResult* r)
      : o_(o), r_(r) {
    layout_.controller = o.chain.mode == ChainMode::kRun && o.chain.controller;
    if (layout_.controller) {
      layout_.vm_dof = Controller(*o.chain.controller).mechanism().dof();
    }
    layout_.truth = dev.truth != nullptr;
    layout_.phases = dev.phases;
  }

  // one record from the ring, in order
  void add(const TickRecord& rec) {
    count(rec);
    if (o_.on_record) o_.on_record(rec);
    if (o_.trace_path.empty()) return;
    if (!writer_) {
      held_.push_back(rec);
      if (rec.state.has(kStateJoints) ||
          rec.t_s - held_.front().t_s >= kHoldForLayoutS) {
        open(rec.state.has(kStateJoints) ? rec.state.present : kStateJoints);
      }
      return;
    }
    writer_->add(rec);
  }

  // the rows so far to the file (each poll; the end)
  void flush(bool last) {
    if (o_.trace_path.empty()) return;
    if (!writer_ && (last || !held_.empty())) {
      if (last) open(kStateJoints);  // never a good reading: joints alone
    }
    if (!writer_) return;
    writer_->flush();
    if (last) writer_->close();
  }

 private:
  void open(std::uint32_t present) {
    layout_.present = present;
    writer_ = std::make_unique<TraceWriter>(o_.trace_path, o_.trace_shown,
                                            layout_);
    for (const TickRecord& h : held_) writer_->add(h);
    held_.clear();
  }

  void count(const TickRecord& s) {
    for (int i = 0; i < kSafetyFlagCount; ++i) {
      if (s.safety & (1u << i)) ++r_->safety_ticks[safety_flag_name(1u << i)];
    }
    if (s.servo.read != DeviceError::kOk) {
      ++r_->read_errors[device_error_name(s.servo.read)];
    } else {
      if (r_->first_reading.present == 0) r_->first_reading = s.state;
      r_->last_reading = s.state;
    }
    if (s.servo.zeroed) ++r_->zeroed_ticks;
    if (s.safety & kSafetyCommLost) {
      if (comm_lost_since_ < 0.0) comm_lost_since_ = s.t_s;
      if (s.t_s - comm_lost_since_ >= o_.give_up_s && !r_->device_gone) {
        r_->device_gone = true;
        gone_error_ = device_error_name(s.servo.read);
      }
    } else {
      comm_lost_since_ = -1.0;
    }
    r_->duration_s = s.t_s;
  }

 public:
  std::string gone_error_;

 private:
  const SessionOptions& o_;
  SessionResult* r_;
  TraceLayout layout_;
  std::unique_ptr<TraceWriter> writer_;
  std::deque<TickRecord> held_;
  double comm_lost_since_ = -1.0;
};

}  // namespace

void configure_controller_session(const ControllerParams& params,
                                  SessionOptions* so) {
  so->chain.mode = ChainMode::kRun;
  so->chain.controller = params;
  so->chain.safety = true;
  const bool deadman = so->chain.safety_params.require_deadman;
  so->chain.safety_params = safety_params_for(params);
  so->chain.safety_params.require_deadman = deadman;
  so->chain.guard.max_period_s = 4.0 * params.servo_period_s;
  so->servo.period_s = params.servo_period_s;
}

void scale_gains(ControllerParams* params, double scale) {
  params->gains.k_pos_N_per_mm *= scale;
  params->gains.k_ornt_Nmm_per_rad *= scale;
  params->gains.k_vel_Ns_per_mm *= scale;
  params->gains.k_vel_ornt_Nmms_per_rad *= scale;
}

SessionResult run_session(OpenedDevice* dev, const SessionOptions& o) {
  DeviceBackend& backend = *dev->backend;
  SessionLoop loop(backend.device(), o.chain, o.servo.period_s, o.duration_s,
                   dev->truth);
  SessionResult r;
  r.clock = servo_clock_name(o.servo);
  Recorder recorder(o, *dev, &r);
  StopSignals signals;
  r.servo_report = backend.start(&loop, o.servo);
  // whatever leaves this function from here on (a callback that throws,
  // memory running out), the loop is stopped before it is destroyed, and
  // the device left at zero torque
  struct StopOnExit {
    DeviceBackend* backend;
    ~StopOnExit() { backend->stop(); }
  } stop_on_exit{&backend};

  TickRecord rec;
  double next_progress_s = 1.0;
  std::string write_error;
  auto drain = [&](bool last) {
    try {
      while (loop.ring().pop(&rec)) recorder.add(rec);
      recorder.flush(last);
    } catch (const std::runtime_error& e) {
      // a full disk: stop rather than drive the device unrecorded
      if (write_error.empty()) write_error = e.what();
    }
  };

  while (backend.running() && !signals.requested() && !r.device_gone &&
         write_error.empty()) {
    backend.pass(kPollS);
    drain(false);
    if (o.on_poll) o.on_poll(r.duration_s);
    if (o.progress && r.duration_s >= next_progress_s) {
      const TickStats t = backend.timing();
      std::fprintf(stderr,
                   "%s: %.1f/%.1f s, %ld ticks, %ld overruns, jitter p99 %.0f us (%s)\n",
                   o.verb.c_str(), r.duration_s, o.duration_s, t.ticks,
                   t.overruns, 1e6 * t.jitter_p99_s, r.clock.c_str());
      next_progress_s += 1.0;
    }
  }
  // the emulator's own stall, asked before it is stopped
  const std::string stall = r.device_gone ? backend.stall_cause() : "";
  backend.stop();  // zero torque at the device
  loop.flush();
  drain(true);
  if (signals.requested()) {
    r.signal = signals.signal_number();
    r.stop_reason = "signal " + signal_name(r.signal);
  } else if (r.device_gone) {
    r.stop_reason = !stall.empty()
                        ? "emulator_stalled: " + stall
                        : "device_gone: no reading for " +
                              std::to_string(o.give_up_s) +
                              " s (last error: " + recorder.gone_error_ + ")";
  } else {
    r.stop_reason = r.duration_s >= o.duration_s - 1.5 * o.servo.period_s
                        ? "duration"
                        : "loop_ended";
  }
  r.ticks = loop.ticks();
  r.dropped = loop.ring().dropped();
  r.timing = backend.timing();
  if (!o.trace_path.empty()) r.trace_path = o.trace_shown;
  if (!write_error.empty()) {
    throw std::runtime_error(o.verb + ": writing the trace failed (" +
                             write_error +
                             "); the device was stopped at zero torque");
  }
  return r;
}

void raise_if_cut_short(const SessionResult& r, const std::string& verb) {
  char when[64];
  std::snprintf(when, sizeof when, "%.3f", r.duration_s);
  if (r.signal != 0) {
    throw SignalStop(verb + ": stopped by " + r.stop_reason.substr(7) +
                         "; zero torque sent, trace kept up to t = " + when +
                         " s",
                     r.signal);
  }
  if (r.device_gone) {
    throw std::runtime_error(verb + ": " + r.stop_reason +
                             "; zero torque sent, trace kept up to t = " +
                             when + " s");
  }
}

LiveSession::LiveSession(OpenedDevice* dev, const ChainOptions& chain,
                         const ServoOptions& servo)
    : dev_(dev),
      loop_(std::make_unique<SessionLoop>(dev->backend->device(), chain,
                                          servo.period_s, 1e300, dev->truth)) {
  dev_->backend->start(loop_.get(), servo);
}

LiveSession::~LiveSession() { stop(); }

void LiveSession::stop() noexcept {
  if (stopped_) return;
  stopped_ = true;
  dev_->backend->stop();
}

TickRecord LiveSession::latest() const { return loop_->latest(); }
long LiveSession::ticks() const { return loop_->ticks(); }

}  // namespace vmh::runtime
