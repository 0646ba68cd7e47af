// The thesis's claims (thesis/claims.cc) on the six thesis scenes: every
// claim of a case, measured on a full run through run_case, holds as a
// measured number on enough ticks.
#include "thesis/claims.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "thesis/run_case.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/thesis_cases.h"

namespace vmh::thesis {
namespace {

std::string claims_scene(int n) { return testing::thesis_case_scene(n); }

using CaseTest = testing::ThesisCaseTest;

// The claims expected to hold on some sides only: case 6's "toward
// X(theta_R)" under the thesis's error (eq. 3.35-3.37 as printed;
// docs/errata.md, erratum 26) holds left of the pivot only (above and below
// it), and "between
// X(theta_V) and X(theta_R), nearer X(theta_V)" only far off the path, in
// the saturated regime (near it the orientation term dominates).
bool expected_partial(int thesis_case, const std::string& claim) {
  return (thesis_case == 6 && claim == "on_path_force_toward_xr") ||
         claim == "off_path_between_nearer_xv";
}

bool off_path_claim(const Claim& c) {
  return c.window.find("off_") != std::string::npos;
}

void check_sides(int thesis_case, const Claim& c) {
  // left and right of the pivot, above and below it, and near the path for
  // an off-path claim
  ASSERT_EQ(c.sides.size(), off_path_claim(c) ? 5u : 4u) << c.name;
  const char* where[] = {"left of the pivot, above it",
                         "right of the pivot, above it",
                         "left of the pivot, below it",
                         "right of the pivot, below it"};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(c.sides[static_cast<std::size_t>(i)].where.rfind(where[i], 0), 0u)
        << c.name << ": " << c.sides[static_cast<std::size_t>(i)].where;
  }
  for (const Claim::Side& s : c.sides) {
    std::printf("  %-36s %s: %.4g (law %.4g, %s, %.1f mm off)%s\n", "",
                s.where.c_str(), s.value, s.prediction.value_or(std::nan("")),
                s.regime.c_str(), s.mean_path_distance_mm,
                s.pass ? "" : " FAILS");
    // the simulation agrees with the law on every side, holding or not
    ASSERT_TRUE(s.prediction.has_value()) << c.name << " " << s.where;
    EXPECT_TRUE(s.matches_prediction.value_or(false))
        << c.name << " " << s.where << ": " << s.value << " vs " << *s.prediction;
  }
  if (off_path_claim(c)) {
    // the held-near side is in the linear regime, the others saturated
    EXPECT_NE(c.sides[4].where.find("near the path"), std::string::npos);
    EXPECT_EQ(c.sides[4].regime, "linear") << c.name;
    EXPECT_LT(c.sides[4].mean_path_distance_mm, 6.0) << c.name;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(c.sides[static_cast<std::size_t>(i)].regime, "saturated")
          << c.name << " " << c.sides[static_cast<std::size_t>(i)].where;
    }
  }
  if (expected_partial(thesis_case, c.name)) {
    EXPECT_FALSE(c.pass) << c.name;
    EXPECT_TRUE(c.partial) << c.name;
    if (off_path_claim(c)) {
      EXPECT_EQ(c.holds_where.find("near the path"), std::string::npos)
          << c.holds_where;
      EXPECT_NE(c.holds_where.find("right of the pivot, above it"),
                std::string::npos)
          << c.holds_where;
      EXPECT_NE(c.holds_where.find("right of the pivot, below it"),
                std::string::npos)
          << c.holds_where;
    } else {
      EXPECT_EQ(c.holds_where,
                "left of the pivot, above it; left of the pivot, below it");
    }
  } else {
    EXPECT_TRUE(c.pass) << c.name << ": " << c.value << " " << c.comparison
                        << " " << c.threshold << " " << c.unit;
    EXPECT_FALSE(c.partial) << c.name;
  }
}

// Each claim of the case (thesis/claims.cc), measured on a full 20 s run
// on each side of the pivot, passes (or holds on the side the thesis's
// formulation allows, where that is expected), and agrees on every side
// with the law's prediction at the true poses; the measured figure goes in
// the log and the XML report.
TEST_P(CaseTest, ThesisClaimsHold) {
  const CaseResult r = run_case("case" + std::to_string(GetParam()),
                                claims_scene(GetParam()), {}, "");
  ASSERT_FALSE(r.claims.empty());
  EXPECT_TRUE(r.all_claims_pass);
  for (const Claim& c : r.claims) {
    std::printf("  case%d %-36s %.4g %s %.4g %s (%d ticks)\n", GetParam(),
                c.name.c_str(), c.value, c.comparison.c_str(), c.threshold,
                c.unit.c_str(), c.samples);
    RecordProperty(c.name, std::to_string(c.value));
    EXPECT_GT(c.samples, 100) << c.name << " measured on too few ticks";
    // and agrees with what the law predicts at the true poses, limits
    // included (thesis/law_prediction.h), in the regime it was tried in
    ASSERT_TRUE(c.prediction.has_value()) << c.name << ": " << c.prediction_note;
    std::printf("  %-36s predicted %.4g +- %.3g, %s (%.0f%% limited)\n", "",
                *c.prediction, c.tolerance, c.regime.c_str(),
                100.0 * c.saturated_fraction);
    EXPECT_TRUE(c.matches_prediction.value_or(false))
        << c.name << ": measured " << c.value << ", predicted "
        << *c.prediction << " +- " << c.tolerance;
    EXPECT_TRUE(c.regime == "linear" || c.regime == "saturated") << c.regime;
    EXPECT_EQ(c.regime == "saturated", c.saturated_fraction >= 0.5);
    check_sides(GetParam(), c);
  }
}

// With the geometric orientation error case 6 holds every claim on all four
// sides of the pivot (left, right, above, below): its partial "toward X(theta_R)" above is the
// thesis's formulation, not the law. (Near the path "nearer X(theta_V)"
// still fails, as for every orientation case.)
TEST(CaseSix, GeometricErrorHoldsOnBothSides) {
  const CaseResult r =
      run_case("case6", claims_scene(6), {"error=geometric"}, "");
  ASSERT_FALSE(r.claims.empty());
  for (const Claim& c : r.claims) {
    ASSERT_GE(c.sides.size(), 4u);
    for (const Claim::Side& s : c.sides) {
      const bool near = s.where.find("near the path") != std::string::npos;
      EXPECT_EQ(s.pass, !(near && c.name == "off_path_between_nearer_xv"))
          << c.name << " " << s.where;
      EXPECT_TRUE(s.matches_prediction.value_or(false)) << c.name << " " << s.where;
    }
    for (int i = 0; i < 4; ++i) {
      EXPECT_TRUE(c.sides[static_cast<std::size_t>(i)].pass)
          << c.name << " " << c.sides[static_cast<std::size_t>(i)].where;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(ThesisCases, CaseTest, ::testing::Range(1, 8));

}  // namespace
}  // namespace vmh::thesis
