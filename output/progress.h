// A progress bar on stderr for the long jobs (run --all, the studies, the
// report): fraction and count done, elapsed time and an estimate of the time
// left from the mean rate so far, redrawn in place with '\r' at most about
// ten times a second.
//
// It draws only when stderr is a terminal, so that logs, pipes and the
// tests' captured output stay clean; a bar given an explicit stream always
// draws (tests). Worker threads call advance() or a part's callback: the
// state is under a small mutex, taken once per finished work item, which is
// far rarer than anything the items themselves do.
#ifndef VMHAPTICS_OUTPUT_PROGRESS_H_
#define VMHAPTICS_OUTPUT_PROGRESS_H_

#include <cstddef>
#include <functional>
#include <mutex>
#include <ostream>
#include <string>
#include <vector>

namespace vmh::output {

// (done, total) of one job: what the studies report as items finish
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

class Progress {
 public:
  // seconds since some fixed instant; steady_clock by default
  using Clock = std::function<double()>;

  // On stderr, drawn only if stderr is a terminal.
  Progress(std::string label, std::size_t total);
  // On `out`, always drawn (null: silent); `clock` empty: steady_clock.
  Progress(std::string label, std::size_t total, std::ostream* out,
           Clock clock = {});
  // finish()es a bar that was not
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // n more items of part 0 done (thread-safe)
  void advance(std::size_t n = 1);

  // A job made of parts, each reporting its own (done, total): the bar
  // shows their sums. part(k) is a callback for part k (k < parts added so
  // far); `estimated_total` stands for a part's total until it reports.
  // Thread-safe, like the callbacks it returns.
  std::size_t add_part(std::size_t estimated_total);
  ProgressFn part(std::size_t k);

  // Draws the final state and ends the line (once; only if drawn at all).
  void finish();

  std::size_t done() const;
  std::size_t total() const;
  bool drawing() const { return out_ != nullptr; }

  // The line as drawn at `elapsed_s` (no '\r'): label, bar, percent,
  // done/total, elapsed and the estimate of the time left.
  static std::string format_line(const std::string& label, std::size_t done,
                                 std::size_t total, double elapsed_s);

 private:
  void update_locked(std::size_t k, std::size_t done, std::size_t total);
  void draw_locked(bool force);
  // the parts' done and total summed (mutex_ held)
  std::size_t done_locked() const;
  std::size_t total_locked() const;

  std::string label_;
  std::ostream* out_;  // null: silent
  Clock clock_;
  double start_s_ = 0.0;
  double last_draw_s_ = -1.0;
  bool finished_ = false;
  bool drew_ = false;
  mutable std::mutex mutex_;
  std::vector<std::size_t> done_;   // per part
  std::vector<std::size_t> total_;  // per part
};

// whether file descriptor `fd` is a terminal: the default bar's one decision
bool is_terminal(int fd);

}  // namespace vmh::output

#endif  // VMHAPTICS_OUTPUT_PROGRESS_H_
