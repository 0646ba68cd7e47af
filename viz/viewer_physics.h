// The viewer's physics thread: one ClosedLoop ticked at its servo period
// in real time (or a quarter of it in slow motion), whatever the frame
// rate.
//
// Pacing: an absolute deadline on the steady clock, advanced by one period
// per tick and slept to (sleep_until). When the thread falls more than
// kMaxCatchUpTicks behind (a slow machine, a suspended process) it drops
// the missed time instead of racing to catch up: the simulation then runs
// slower than real time, which the real-time factor shows, but it never
// spirals.
//
// Sharing: the loop is ticked under mutex_, and the render thread takes the
// same lock only to copy what a frame needs (copy()): a few microseconds of
// mj_copyData on the Omni model. Commands (pause, step, reset, the manual
// target) take it as briefly.
#ifndef VMHAPTICS_VIZ_VIEWER_PHYSICS_H_
#define VMHAPTICS_VIZ_VIEWER_PHYSICS_H_

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "sim/closed_loop.h"

namespace vmh::viz {

// one point of the live plots
struct PlotSample {
  float t_s = 0.0f;
  float d_path_mm = 0.0f;  // the RM's distance to the VM's path
  float force_N = 0.0f;    // |F| commanded
};

inline constexpr int kPlotSamples = 1000;     // mjMAXLINEPNT
inline constexpr double kPlotWindow_s = 5.0;  // what the plots span
inline constexpr int kPlotYIntervals = 2;    // grid intervals up the y axis
inline constexpr int kMaxCatchUpTicks = 5;

class SimThread {
 public:
  // Takes the loop; does not start.
  explicit SimThread(std::unique_ptr<sim::ClosedLoop> loop);
  ~SimThread();  // stops
  SimThread(const SimThread&) = delete;
  SimThread& operator=(const SimThread&) = delete;

  void start();
  void stop();

  // The model (fixed while the thread lives: only data is stepped).
  const mjModel* model() const { return loop_->model(); }
  const sim::ClosedLoop& loop() const { return *loop_; }

  // What a frame copies: the state into *d (made for model()), the last
  // tick's row, and the plot samples, oldest first, into plots[0..*n).
  void copy(mjData* d, TickRecord* row, bool* ticked,
            std::array<PlotSample, kPlotSamples>* plots, int* n);

  void set_paused(bool on);
  bool paused() const { return paused_.load(); }
  // one servo tick while paused
  void step_once();
  // simulated seconds per wall second (1, or 0.25 in slow motion)
  void set_speed(double factor);
  void reset();
  void set_manual_hand(bool on);
  sim::HandTargetState manual_target();
  void set_manual_target(const sim::HandTargetState& t);

 private:
  void run();
  void record_plot();

  std::unique_ptr<sim::ClosedLoop> loop_;
  std::mutex mutex_;  // guards loop_'s state, row_, the plot ring
  TickRecord row_;
  bool ticked_ = false;
  std::array<PlotSample, kPlotSamples> ring_{};
  int ring_head_ = 0, ring_count_ = 0;
  int plot_every_ = 5;  // ticks per plot sample
  long ticks_ = 0;
  int step_requests_ = 0;
  std::atomic<bool> paused_{false};
  std::atomic<double> speed_{1.0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_VIEWER_PHYSICS_H_
