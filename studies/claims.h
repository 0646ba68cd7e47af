// The thesis's claims (ch. 4, docs/sources.md §2) as measured numbers on a
// closed-loop run, and the run's metrics.
//
// Each claim names what it measures, over which part of the hand script
// (the settled second half of a hold), the measured value, the threshold and
// the comparison. Thresholds are stated once, here, with their reasoning in
// docs/testbed.md.
#ifndef VMHAPTICS_STUDIES_CLAIMS_H_
#define VMHAPTICS_STUDIES_CLAIMS_H_

#include <optional>
#include <string>
#include <vector>

#include "sim/closed_loop.h"

namespace vmh::studies {

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
};

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

RunMetrics run_metrics(const std::vector<sim::TraceRow>& rows,
                       const sim::ClosedLoop& loop);

// The gains a case's claims compare against (case 2's for cases 3 and 4),
// if any.
std::optional<ControllerParams> reference_params(int thesis_case,
                                                 const ControllerParams& p);

// The claims of thesis case 1..6 measured on `rows` (empty for 0).
std::vector<Claim> evaluate_claims(int thesis_case,
                                   const std::vector<sim::TraceRow>& rows,
                                   const sim::ClosedLoop& loop);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_CLAIMS_H_
