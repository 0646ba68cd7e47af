// thesis/side_runs.h: a case's other sides simulate only what their claims
// read. Checked here: which segments a side's plan reads (from the claims'
// windows, against the segment names written out), that a fitted side
// stops after the last of them, that a settled hold ends early and is
// still measured in its settled half, that the script's clock only moves
// forward, and that the claims of a fitted side match those of the full
// run of the same side within the bounds docs/testbed.md states.
#include "thesis/side_runs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "sim/closed_loop.h"

namespace vmh::thesis {
namespace {

std::string scene(int n) {
  return std::string(VMH_MODELS_DIR) + "/cases/case" + std::to_string(n) + ".xml";
}

// the main run of a case, its claims (their windows name what a side reads)
std::vector<Claim> main_claims(sim::ClosedLoop* loop) {
  const SidePlan every{std::vector<char>(loop->script().segments().size(), 1),
                       static_cast<int>(loop->script().segments().size()) - 1};
  std::vector<TickRecord> rows;
  run_side(loop, every, SideMode::kFull, {}, nullptr, nullptr, &rows);
  return evaluate_claims(loop->config().thesis_case, rows, loop->the_case());
}

std::set<std::string> read_names(const sim::HandScript& s, const SidePlan& p) {
  std::set<std::string> names;
  for (std::size_t k = 0; k < p.read.size(); ++k) {
    if (p.read[k]) names.insert(s.segments()[k].name);
  }
  return names;
}

// Case 1 (position only) reads the on-path and off-path holds; the near-
// path side feeds only the off-path claims. Case 4 reads the sweep too,
// the script's last segment.
TEST(SideRuns, PlansReadTheSegmentsOfTheClaimsWindows) {
  sim::ClosedLoop c1(scene(1), {});
  const std::vector<Claim> claims1 = main_claims(&c1);
  ASSERT_FALSE(claims1.empty());
  const SidePlan all = plan_side(c1.script(), claims1, false);
  EXPECT_EQ(read_names(c1.script(), all),
            (std::set<std::string>{"off_out", "off_out_misaligned", "off_in",
                                   "on_misaligned_a", "on_misaligned_b"}));
  const SidePlan off = plan_side(c1.script(), claims1, true);
  EXPECT_EQ(read_names(c1.script(), off),
            (std::set<std::string>{"off_out", "off_out_misaligned", "off_in"}));
  EXPECT_LT(off.last_read, all.last_read);
  EXPECT_LT(all.last_read,
            static_cast<int>(c1.script().segments().size()) - 1);

  sim::ClosedLoop c4(scene(4), {});
  const SidePlan p4 = plan_side(c4.script(), main_claims(&c4), false);
  EXPECT_TRUE(read_names(c4.script(), p4).count("sweep"));
  EXPECT_EQ(p4.last_read, static_cast<int>(c4.script().segments().size()) - 1);
  // no claims, nothing read
  EXPECT_EQ(plan_side(c4.script(), {}, false).last_read, -1);
}

// A fitted side stops at the end of the last segment it reads, and every
// row it returns is one the claims read: in a read segment's settled half.
TEST(SideRuns, AFittedSideStopsAfterItsLastReadSegment) {
  sim::ClosedLoop first(scene(2), {});
  const std::vector<Claim> claims = main_claims(&first);
  sim::ClosedLoop side(scene(2), {});
  const SidePlan plan = plan_side(side.script(), claims, false);
  SideStats st;
  std::vector<TickRecord> rows;
  run_side(&side, plan, SideMode::kFitted, {}, nullptr, &st, &rows);
  const sim::ScriptSegment& last =
      side.script().segments()[static_cast<std::size_t>(plan.last_read)];
  EXPECT_NEAR(st.script_s, last.t1_s, 1.5e-3);
  EXPECT_LT(st.script_s, side.config().sim.duration_s - 1.0);
  EXPECT_LE(st.physics_s, st.script_s + 1e-9);
  EXPECT_EQ(st.ticks, static_cast<std::int64_t>(std::llround(st.physics_s / 1e-3)));
  ASSERT_FALSE(rows.empty());
  for (const TickRecord& r : rows) {
    const sim::ScriptSegment& s =
        side.script().segments()[static_cast<std::size_t>(r.segment)];
    ASSERT_TRUE(plan.read[static_cast<std::size_t>(r.segment)]) << s.name;
    ASSERT_GE(r.t_s, s.settled_from_s()) << s.name;
  }
}

// Where the plant does come to rest (case 1 with the joints' dry friction
// off and no quantisation: tests/sim/scenes/case1_smooth.xml at the case
// scenes' 1 ms step), holds end once settled: less physics than script,
// each settled hold the claims read measured over kMeasuredTicks ticks of
// its settled half, and the claims the same as the full run's within the
// stated bounds.
TEST(SideRuns, SettledHoldsEndEarly) {
  const std::string smooth =
      std::string(VMH_TEST_SCENES_DIR) + "/case1_smooth.xml";
  const std::vector<std::string> o = {"quantize=0", "physics_step_s=0.001"};
  sim::ClosedLoop first(smooth, o);
  const std::vector<Claim> claims = main_claims(&first);
  ASSERT_FALSE(claims.empty());

  sim::ClosedLoop fitted(smooth, o);
  const SidePlan plan = plan_side(fitted.script(), claims, false);
  SideStats st;
  std::vector<TickRecord> rows;
  run_side(&fitted, plan, SideMode::kFitted, {}, nullptr, &st, &rows);
  EXPECT_GE(st.holds_settled, 3);
  EXPECT_LT(st.physics_s, st.script_s - 1.0);
  // per read hold: either measured whole (not settled) or kMeasuredTicks
  // ticks at least, all in its settled half
  for (std::size_t k = 0; k < plan.read.size(); ++k) {
    if (!plan.read[k]) continue;
    int n = 0;
    for (const TickRecord& r : rows) n += r.segment == static_cast<int>(k);
    EXPECT_GE(n, kMeasuredTicks) << fitted.script().segments()[k].name;
  }
  const std::vector<Claim> got =
      evaluate_claims(1, rows, fitted.the_case());
  ASSERT_EQ(got.size(), claims.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].pass, claims[i].pass) << got[i].name;
    // the bounds of run_case_test's figure_bound (docs/testbed.md)
    const double bound = got[i].unit == "N"     ? 0.005
                         : got[i].unit == "deg" ? 0.5
                                                : 0.05 * std::max(1.0, std::abs(got[i].threshold));
    EXPECT_NEAR(got[i].value, claims[i].value, bound) << got[i].name;
  }
}

// The script's clock moves forward only, and within the script.
TEST(SideRuns, TheScriptClockMovesForwardOnly) {
  sim::ClosedLoop loop(scene(1), {});
  TickRecord row;
  for (int i = 0; i < 10; ++i) loop.tick(&row);
  EXPECT_NEAR(loop.script_time_s(), 0.010, 1e-12);
  loop.skip_script_to(5.0);
  EXPECT_NEAR(loop.script_time_s(), 5.0, 1e-12);
  EXPECT_NEAR(loop.time_s(), 0.010, 1e-12);
  loop.tick(&row);
  EXPECT_NEAR(row.t_s, 5.0, 1e-12);  // the record carries the script's time
  EXPECT_THROW(loop.skip_script_to(4.0), std::invalid_argument);
  EXPECT_THROW(loop.skip_script_to(loop.config().sim.duration_s + 1.0),
               std::invalid_argument);
  loop.skip_script_to(loop.config().sim.duration_s);
  EXPECT_TRUE(loop.finished());
  loop.reset();
  EXPECT_EQ(loop.script_time_s(), 0.0);
}

}  // namespace
}  // namespace vmh::thesis
