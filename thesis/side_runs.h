// The other sides of a case: run_case() runs each case again with its start
// pose mirrored left to right, from below the pivot, and with the off-path
// holds nearer the path (docs/testbed.md, "Sides"), so that no claim passes
// by the side it was tried on. A side's run feeds only its claims, so it
// simulates only what they read:
//
// - it ends with the last script segment a claim of it reads (plan_side():
//   the claims' own windows, by name), not at the script's end;
// - a hold whose target stands still (after its blend-in) ends once the
//   plant has settled, by a stated criterion: every joint slower than
//   kSettledSpeedRadS for kSettledTicks ticks in a row. A hold the claims
//   read is then measured over kMeasuredTicks ticks inside its settled
//   half (the script's clock moved to that half first, if needed); then
//   the script's clock moves on to the hold's end
//   (sim::ClosedLoop::skip_script_to);
// - it writes a trace only when asked (run --trace-sides).
//
// SideMode::kFull runs the side as the main run is run, the whole script,
// every tick simulated: what `run --sides full` asks for, and what the
// tests bound the fitted runs' figures against.
#ifndef VMHAPTICS_THESIS_SIDE_RUNS_H_
#define VMHAPTICS_THESIS_SIDE_RUNS_H_

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/trace_writer.h"
#include "thesis/claims.h"
#include "thesis/run_case.h"

namespace vmh::thesis {

// SideMode (run_case.h): "fitted" or "full"
const char* side_mode_name(SideMode m);

// The settle criterion: the plant has settled in a hold once every joint
// (the true ones, MuJoCo's qvel) has been slower than kSettledSpeedRadS
// for kSettledTicks servo ticks in a row. 2e-4 rad/s moves the wrist
// centre less than 0.03 mm/s; a looser 2e-3 rad/s over 50 ticks ended
// holds while the arm still crept (stick-slip against the joints' dry
// friction) and moved on_path_no_force by 0.016 N of its 0.05 N threshold.
inline constexpr double kSettledSpeedRadS = 2e-4;
inline constexpr int kSettledTicks = 100;
// ticks measured in a settled hold's settled half before it ends
inline constexpr int kMeasuredTicks = 200;

// What a side's run simulates: per script segment, whether a claim reads
// it; and the last such segment, with which the run ends (-1: none).
struct SidePlan {
  std::vector<char> read;
  int last_read = -1;
};

// The plan for a side whose claims are `claims` (the main run's, whose
// windows name the segments they read). `off_path_only`: the side feeds
// only the claims measured off the path (SideRun::off_path_only).
SidePlan plan_side(const sim::HandScript& script,
                   const std::vector<Claim>& claims, bool off_path_only);

// What a side's run did, for summary.json's "sides".
struct SideStats {
  double physics_s = 0.0;  // simulated time
  double script_s = 0.0;   // script time covered (skips included)
  std::int64_t ticks = 0;
  int holds_settled = 0;   // holds the settle criterion ended early
  double wall_time_s = 0.0;
};

// Makes room for n rows in *rows (empty: what it held is not kept) and, on
// Linux, asks for its memory in 2 MB pages: a case's 20,000 rows are 31 MB,
// whose 7,500 first touches as 4 kB pages took a twentieth of run --all
// (the kernel zeroes the same bytes either way; it is the faults that
// cost). A hint only: without transparent huge pages nothing changes.
void reserve_rows(std::vector<TickRecord>* rows, std::size_t n);

// Sets the loop's reference gains where the case's claims compare with
// case 2's (reference_params()); every run of a case does this first.
void use_reference_gains(sim::ClosedLoop* loop);

// Runs `loop`, from its start, as a side (use_reference_gains() included):
// every tick goes to `trace` (if set); the ticks the plan's claims read
// replace *rows (whose memory a caller may reuse from run to run). Throws
// PhysicsError on a bad physics state, runtime::Interrupted when `stop` says
// so.
void run_side(sim::ClosedLoop* loop, const SidePlan& plan, SideMode mode,
              const runtime::StopFn& stop, runtime::TraceWriter* trace,
              SideStats* stats, std::vector<TickRecord>* rows);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_SIDE_RUNS_H_
