// The thesis's claims (ch. 4, docs/sources.md §2) as measured numbers on a
// closed-loop run, and the run's metrics.
//
// Each claim names what it measures, over which part of the hand script
// (the settled second half of a hold), the measured value, the threshold and
// the comparison. Thresholds are stated once, here, with their reasoning in
// docs/testbed.md.
#ifndef VMHAPTICS_THESIS_CLAIMS_H_
#define VMHAPTICS_THESIS_CLAIMS_H_

#include <optional>
#include <set>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/cases/case.h"

namespace vmh::thesis {

struct Claim {
  std::string name;
  std::string statement;  // the thesis's words, shortened
  std::string window;     // the script segments it is measured over
  double value = 0.0;
  std::string comparison;  // "<=" or ">="
  double threshold = 0.0;
  std::string unit;
  int samples = 0;  // servo ticks it was measured on
  // mean distance of the RM from the path over the window: the claims about
  // "off the path" depend on how far off (docs/testbed.md)
  double mean_path_distance_mm = 0.0;
  bool pass = false;
  // The same measure on the force the law gives at the window's ground-
  // truth poses, limits included (thesis/law_prediction.h), and whether
  // the measured value is within `tolerance` of it (in the claim's unit).
  // No prediction where the law has no closed form there; `prediction_note`
  // says how it is computed or why there is none.
  std::optional<double> prediction;
  double tolerance = 0.0;
  std::optional<bool> matches_prediction;
  std::string prediction_note;
  // the window's ticks whose force or torque was limited, and the regime
  // they make: "saturated" when at least half were, else "linear"
  double saturated_fraction = 0.0;
  std::string regime = "linear";
  // The sides of the pivot the case was run on (run_case runs it again
  // with the start pose mirrored left to right, so that no claim passes by
  // the side it was tried on), each with its own figures. `value`,
  // `prediction` and the rest above are the first side's; `pass` holds
  // only if the claim holds on every side, and `partial` if on some, with
  // `holds_where` naming them. Empty when only one side was run.
  struct Side {
    std::string where;
    double value = 0.0;
    bool pass = false;
    std::optional<double> prediction;
    std::optional<bool> matches_prediction;
    std::string regime;
    double mean_path_distance_mm = 0.0;
  };
  std::vector<Side> sides;
  bool partial = false;
  std::string holds_where;
};

// The script segments a claim is measured over (Claim::window, split at
// its commas).
std::set<std::string> window_segments(const Claim& c);
// Whether a claim is measured over the off-path holds (its window names
// off_out, off_out_misaligned or off_in): the claims a near-path side
// feeds (SideRun::off_path_only).
bool measured_off_path(const Claim& c);

// Where a run of a case was tried, as a side's label.
struct SideLabel {
  std::string where;           // the side, for every claim
  std::string where_off_path;  // the same for the off-path claims
};

// The claims of one more run of the same case (the script mirrored, or
// held nearer the path), as a side of each claim in `first`.
struct SideRun {
  SideLabel label;
  std::vector<Claim> claims;
  // the run only changes the off-path holds: it is a side of the claims
  // measured over them (windows off_out, off_out_misaligned, off_in) only
  bool off_path_only = false;
};

// Makes `first` (the claims of the run as given, labelled where_first) and
// the claims of `others` (matched by name) sides of each claim, and sets
// pass, partial and holds_where from them.
void merge_sides(std::vector<Claim>* first, const SideLabel& where_first,
                 const std::vector<SideRun>& others);

struct RunMetrics {
  int ticks = 0;
  // distance of the RM wrist centre from the VM's path, after the settle
  double rms_path_error_mm = 0.0;
  double max_path_error_mm = 0.0;
  // |X_V - p|: the controller's own position error
  double rms_xv_error_mm = 0.0;
  double mean_force_N = 0.0;
  double rms_force_N = 0.0;
  double max_force_N = 0.0;
  double time_on_path_s = 0.0;  // within kOnPathMm of the path
  int force_saturated_ticks = 0;
  int torque_saturated_ticks = 0;
  int fault_ticks = 0;
  int placement_not_converged_ticks = 0;
  int max_placement_iterations = 0;
};

// within this distance (mm) the RM counts as on the path for time_on_path_s
inline constexpr double kOnPathMm = 1.0;

// RunMetrics over a run's ticks, one at a time (memory does not grow with
// the run).
class MetricsAccumulator {
 public:
  explicit MetricsAccumulator(const sim::Case& the_case);
  void add(const TickRecord& r);
  RunMetrics result() const;

 private:
  double T_s_;
  bool has_settle_;
  RunMetrics m_;
  std::int64_t n_ = 0;
  double sum_d2_ = 0.0, sum_xv2_ = 0.0, sum_f_ = 0.0, sum_f2_ = 0.0;
};

// RunMetrics over all of `rows`.
RunMetrics run_metrics(const std::vector<TickRecord>& rows,
                       const sim::Case& the_case);

// The gains a case's claims compare against (case 2's for cases 3 and 4),
// if any.
std::optional<ControllerParams> reference_params(int thesis_case,
                                                 const ControllerParams& p);

// The claims of thesis case 1..6 measured on `rows` (empty for 0).
std::vector<Claim> evaluate_claims(int thesis_case,
                                   const std::vector<TickRecord>& rows,
                                   const sim::Case& the_case);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_CLAIMS_H_
