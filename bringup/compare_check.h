// What `vmhaptics compare` reports: checks with a value against a
// threshold, the faults they point to, and the figures drawn.
//
// Each analysis (kinematics, Jacobian, force direction, closed loop)
// returns a CompareSection; cli/compare.cc gathers them into one JSON
// object (docs/outputs.md, "compare").
#ifndef VMHAPTICS_BRINGUP_COMPARE_CHECK_H_
#define VMHAPTICS_BRINGUP_COMPARE_CHECK_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace vmh::bringup {

// One check: passes when value <= threshold (or, for kAtLeast, when
// value >= threshold). A value that could not be computed (NaN) fails.
struct CompareCheck {
  enum Sense { kAtMost, kAtLeast };
  std::string name;       // "kinematics.position_error_p95", ...
  bool pass = false;
  double value = 0.0;
  double threshold = 0.0;
  std::string unit;       // "mm", "deg", "ms", "ratio", ...
  Sense sense = kAtMost;
  std::string recording;  // the recording directory it was computed on
  std::string detail;     // one line for a human
};

// Builds a check and sets pass from value, threshold and sense
CompareCheck make_check(std::string name, double value, double threshold,
                        std::string unit, CompareCheck::Sense sense =
                                              CompareCheck::kAtMost,
                        std::string detail = {});

// A fault a check points to, named from compare's vocabulary
// (docs/bringup.md, "What compare names"): joint<N>_sign, gimbal_swap,
// link_length_<P>pct, delay_<M>ms, motor<N>_sign, motor3_relative,
// torque_units_Nm, torque_units_mNm, ...
struct SuspectedFault {
  std::string name;
  std::string evidence;   // one line: which check, what value
  std::string recording;
};

// A check not run, and why (the recording lacks what it needs)
struct SkippedCheck {
  std::string name;
  std::string reason;
  std::string recording;
};

struct CompareSection {
  std::string name;  // "kinematics", "jacobian", "force_direction", ...
  std::vector<CompareCheck> checks;
  std::vector<SkippedCheck> skipped;
  std::vector<SuspectedFault> faults;
  nlohmann::ordered_json detail = nlohmann::ordered_json::object();
  std::vector<std::string> figures;  // paths written
};

nlohmann::ordered_json check_json(const CompareCheck& c);
nlohmann::ordered_json section_json(const CompareSection& s);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_COMPARE_CHECK_H_
