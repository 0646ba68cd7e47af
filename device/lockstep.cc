#include "device/lockstep.h"

#include <cmath>
#include <stdexcept>

namespace vmh {

LockstepDriver::LockstepDriver(double period_s)
    : period_s_(period_s), timer_(period_s) {}

void LockstepDriver::start(ServoLoop* loop, LockstepPlant* plant) noexcept {
  loop_ = loop;
  plant_ = plant;
  k_ = 0;
  timer_.reset();
  running_ = loop_ != nullptr && plant_ != nullptr;
}

void LockstepDriver::pass(double dt_s) noexcept {
  const double n_ticks = std::round(dt_s / period_s_);
  std::int64_t n = n_ticks >= 1.0 && std::isfinite(n_ticks)
                       ? static_cast<std::int64_t>(n_ticks)
                       : 1;
  while (running_ && n-- > 0) {
    // the loop's time is k T, a product (not a running sum), so that tick
    // k's time is the simulated loop's to the bit
    const double now_s = static_cast<double>(k_) * period_s_;
    const double wall0_s = monotonic_now_s();
    timer_.begin(now_s);
    const bool more = loop_->tick(now_s);
    if (more) plant_->advance_period();
    timer_.end(now_s + (monotonic_now_s() - wall0_s));
    ++k_;
    if (!more) running_ = false;
  }
}

}  // namespace vmh
