// The case scenes (models/cases/caseN.xml: the thesis's six and case 7, the
// line slider) for tests that run
// them, and a fixture parameterised by the case number that records MuJoCo's
// errors and warnings (mujoco_guard.h). The test needs VMH_MODELS_DIR.
#ifndef VMHAPTICS_TESTS_SUPPORT_THESIS_CASES_H_
#define VMHAPTICS_TESTS_SUPPORT_THESIS_CASES_H_

#include <gtest/gtest.h>

#include <string>

#include "tests/support/mujoco_guard.h"

namespace vmh::testing {

// models/cases/case<n>.xml
inline std::string thesis_case_scene(int n) {
  return std::string(VMH_MODELS_DIR) + "/cases/case" + std::to_string(n) +
         ".xml";
}

// TEST_P(ThesisCaseTest, ...) with INSTANTIATE_TEST_SUITE_P over 1..6 (the
// thesis's), or 1..7 with the line slider
class ThesisCaseTest : public ::testing::TestWithParam<int> {
 protected:
  MujocoGuard guard_;
};

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_THESIS_CASES_H_
