// The thesis's claims (studies/claims.cc) on the six thesis scenes: every
// claim of a case, measured on a full run through run_case, holds as a
// measured number on enough ticks.
#include "studies/claims.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "studies/run_case.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/thesis_cases.h"

namespace vmh::studies {
namespace {

std::string scene(int n) { return testing::thesis_case_scene(n); }

using CaseTest = testing::ThesisCaseTest;

// Each claim of the case (studies/claims.cc), measured on a full 20 s run,
// passes; the measured figure goes in the log and the XML report.
TEST_P(CaseTest, ThesisClaimsHold) {
  const CaseResult r = run_case("case" + std::to_string(GetParam()),
                                scene(GetParam()), {}, "");
  ASSERT_FALSE(r.claims.empty());
  for (const Claim& c : r.claims) {
    std::printf("  case%d %-36s %.4g %s %.4g %s (%d ticks)\n", GetParam(),
                c.name.c_str(), c.value, c.comparison.c_str(), c.threshold,
                c.unit.c_str(), c.samples);
    RecordProperty(c.name, std::to_string(c.value));
    EXPECT_TRUE(c.pass) << c.name << ": " << c.value << " " << c.comparison
                        << " " << c.threshold << " " << c.unit;
    EXPECT_GT(c.samples, 100) << c.name << " measured on too few ticks";
  }
}

INSTANTIATE_TEST_SUITE_P(ThesisCases, CaseTest, ::testing::Range(1, 7));

}  // namespace
}  // namespace vmh::studies
