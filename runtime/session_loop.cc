#include "runtime/session_loop.h"

namespace vmh::runtime {

SessionLoop::SessionLoop(HapticDevice* device, const ChainOptions& chain,
                         double period_s, double duration_s,
                         const TruthSource* truth)
    : chain_(device, chain),
      truth_(truth),
      period_s_(period_s),
      duration_s_(duration_s),
      ring_(kRingCapacity) {}

void SessionLoop::push_pending(double now_s) noexcept {
  if (!pending_) return;
  // the tick's length: to the next tick (the nominal period for the last)
  rec_.period_s = now_s >= 0.0 ? now_s - t0_s_ - rec_.t_s : period_s_;
  if (truth_ != nullptr) {
    truth_->read_truth(&rec_);
    rec_.has_truth = true;
  }
  ring_.push(rec_);
  latest_.write(rec_);
  pending_ = false;
}

bool SessionLoop::tick(double now_s) noexcept {
  if (!started_) {
    t0_s_ = now_s;
    started_ = true;
  }
  push_pending(now_s);
  const double t_s = now_s - t0_s_;
  if (t_s >= duration_s_ - 0.5 * period_s_) return false;
  chain_.tick(t_s, now_s, &rec_);
  pending_ = true;
  ticks_.store(ticks_.load(std::memory_order_relaxed) + 1,
               std::memory_order_release);
  return true;
}

void SessionLoop::flush() noexcept { push_pending(-1.0); }

}  // namespace vmh::runtime
