#include "viz/viewer_physics.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vmh::viz {

SimThread::SimThread(std::unique_ptr<sim::ClosedLoop> loop)
    : loop_(std::move(loop)) {
  // samples spread over the plot window at the case's servo period
  const double T = loop_->controller_params().servo_period_s;
  plot_every_ = std::max(
      1, static_cast<int>(std::ceil(kPlotWindow_s / (T * kPlotSamples))));
}

SimThread::~SimThread() { stop(); }

void SimThread::start() {
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void SimThread::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void SimThread::run() {
  using Clock = std::chrono::steady_clock;
  const double T = loop_->controller_params().servo_period_s;
  Clock::time_point next = Clock::now();
  while (!stop_.load(std::memory_order_relaxed)) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      bool tick = !paused_.load();
      if (!tick && step_requests_ > 0) {
        --step_requests_;
        tick = true;
      }
      if (tick) {
        loop_->tick(&row_);
        ticked_ = true;
        if (++ticks_ % plot_every_ == 0) record_plot();
      }
    }
    const auto period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(T / speed_.load()));
    next += period;
    const Clock::time_point now = Clock::now();
    // too far behind: drop the missed time rather than spiral
    if (now - next > kMaxCatchUpTicks * period) next = now;
    std::this_thread::sleep_until(next);
  }
}

void SimThread::record_plot() {
  PlotSample& s = ring_[static_cast<std::size_t>(ring_head_)];
  s.t_s = static_cast<float>(row_.t_s);
  s.d_path_mm = static_cast<float>(row_.d_path_mm);
  s.force_N = static_cast<float>(row_.out.force_device_N.norm());
  ring_head_ = (ring_head_ + 1) % kPlotSamples;
  if (ring_count_ < kPlotSamples) ++ring_count_;
}

void SimThread::copy(mjData* d, TickRecord* row, bool* ticked,
                     std::array<PlotSample, kPlotSamples>* plots, int* n) {
  std::lock_guard<std::mutex> lock(mutex_);
  mj_copyData(d, loop_->model(), loop_->data());
  *row = row_;
  *ticked = ticked_;
  const int first = (ring_head_ - ring_count_ + kPlotSamples) % kPlotSamples;
  for (int i = 0; i < ring_count_; ++i) {
    (*plots)[static_cast<std::size_t>(i)] =
        ring_[static_cast<std::size_t>((first + i) % kPlotSamples)];
  }
  *n = ring_count_;
}

void SimThread::set_paused(bool on) {
  std::lock_guard<std::mutex> lock(mutex_);
  paused_ = on;
  step_requests_ = 0;
}

void SimThread::step_once() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (paused_) ++step_requests_;
}

void SimThread::set_speed(double factor) { speed_ = factor; }

void SimThread::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  loop_->reset();
  row_ = TickRecord{};
  ticked_ = false;
  ticks_ = 0;
  ring_head_ = ring_count_ = 0;
}

void SimThread::set_manual_hand(bool on) {
  std::lock_guard<std::mutex> lock(mutex_);
  loop_->set_manual_hand(on);
}

sim::HandTargetState SimThread::manual_target() {
  std::lock_guard<std::mutex> lock(mutex_);
  return loop_->manual_target();
}

void SimThread::set_manual_target(const sim::HandTargetState& t) {
  std::lock_guard<std::mutex> lock(mutex_);
  loop_->set_manual_target(t);
}

}  // namespace vmh::viz
