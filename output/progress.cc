#include "output/progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace vmh::output {
namespace {

// redraw at most this often, s: the terminal need not see every item
constexpr double kRedrawInterval_s = 0.1;
constexpr int kBarWidth = 24;

double steady_now_s() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// 83 -> "1:23", 3725 -> "1:02:05"
std::string clock_text(double s) {
  if (!std::isfinite(s) || s < 0.0) return "--:--";
  const long t = std::lround(s);
  char buf[32];
  if (t >= 3600) {
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60,
                  t % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  }
  return buf;
}

}  // namespace

bool is_terminal(int fd) { return isatty(fd) == 1; }

Progress::Progress(std::string label, std::size_t total)
    : Progress(std::move(label), total, nullptr) {
  if (is_terminal(fileno(stderr))) {
    out_ = &std::cerr;
    if (total > 0) draw_locked(true);
  }
}

Progress::Progress(std::string label, std::size_t total, std::ostream* out,
                   Clock clock)
    : label_(std::move(label)),
      out_(out),
      clock_(clock ? std::move(clock) : Clock(steady_now_s)),
      done_{0},
      total_{total} {
  start_s_ = clock_();
  // shown at once, so that a slow first item is not mistaken for a hang
  if (total > 0) draw_locked(true);
}

Progress::~Progress() { finish(); }

void Progress::advance(std::size_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  update_locked(0, done_[0] + n, total_[0]);
}

std::size_t Progress::add_part(std::size_t estimated_total) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_.push_back(0);
  total_.push_back(estimated_total);
  draw_locked(false);
  return done_.size() - 1;
}

ProgressFn Progress::part(std::size_t k) {
  return [this, k](std::size_t done, std::size_t total) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (k < done_.size()) update_locked(k, done, total);
  };
}

void Progress::update_locked(std::size_t k, std::size_t done,
                             std::size_t total) {
  // a part never goes back, and never past its total
  total_[k] = total;
  done_[k] = std::min(std::max(done_[k], done), total);
  draw_locked(false);
}

std::size_t Progress::done_locked() const {
  std::size_t s = 0;
  for (std::size_t d : done_) s += d;
  return s;
}

std::size_t Progress::total_locked() const {
  std::size_t s = 0;
  for (std::size_t t : total_) s += t;
  return s;
}

std::size_t Progress::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_locked();
}

std::size_t Progress::total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return total_locked();
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_ || out_ == nullptr) {
    finished_ = true;
    return;
  }
  draw_locked(true);
  *out_ << '\n' << std::flush;
  finished_ = true;
}

void Progress::draw_locked(bool force) {
  if (out_ == nullptr || finished_) return;
  const std::size_t done = done_locked();
  const std::size_t total = total_locked();
  const double now = clock_();
  if (!force && done < total && drew_ &&
      now - last_draw_s_ < kRedrawInterval_s) {
    return;
  }
  last_draw_s_ = now;
  drew_ = true;
  // "\x1b[K" clears what a longer previous line left
  *out_ << '\r' << format_line(label_, done, total, now - start_s_)
        << "\x1b[K" << std::flush;
}

std::string Progress::format_line(const std::string& label, std::size_t done,
                                  std::size_t total, double elapsed_s) {
  const double frac =
      total > 0
          ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total))
          : 0.0;
  const int filled = static_cast<int>(std::floor(frac * kBarWidth));
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kBarWidth, '.');
  // the mean rate so far; none before the first item
  const double eta_s =
      done > 0 ? elapsed_s / static_cast<double>(done) *
                     static_cast<double>(total - std::min(done, total))
               : NAN;
  char buf[160];
  std::snprintf(buf, sizeof buf, " [%s] %3d%% %zu/%zu  elapsed %s  eta %s",
                bar.c_str(), static_cast<int>(std::floor(100.0 * frac)), done,
                total, clock_text(elapsed_s).c_str(),
                clock_text(eta_s).c_str());
  return label + buf;
}

}  // namespace vmh::output
