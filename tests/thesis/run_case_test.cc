// thesis/run_case.h: one case run to its end. What `run` writes is checked
// by tests/cli/run_test.cc; here, what the library does with MuJoCo's
// warnings and with a physics state gone bad.
#include "runtime/trace_writer.h"
#include "thesis/run_case.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "sim/mujoco_messages.h"

namespace vmh::thesis {
namespace {

std::string case1() { return std::string(VMH_MODELS_DIR) + "/cases/case1.xml"; }

// summary.json's "mujoco_warnings": the per-step counters by name, plus what
// else MuJoCo said; every text once, with how often it came
TEST(MujocoWarningsJson, CountsKindsAndKeepsTheTexts) {
  std::array<std::int64_t, mjNWARNING> per_step{};
  per_step[mjWARN_CONTACTFULL] = 250;
  per_step[mjWARN_BADQACC] = 2;
  sim::MujocoWarningTally said;
  said.add("Pre-allocated contact buffer is full. Increase nconmax above 10. "
           "Time = 0.0010.");
  said.add("Nan, Inf or huge value in QACC at DOF 1. The simulation is "
           "unstable. Time = 0.0020.");
  said.add("Nan, Inf or huge value in QACC at DOF 2. The simulation is "
           "unstable. Time = 0.0030.");
  said.add("a plugin said so");
  const nlohmann::json j = mujoco_warnings_json(per_step, said);
  EXPECT_EQ(j.at("count"), 250 + 2 + 1);
  EXPECT_EQ(j.at("kinds"),
            nlohmann::json({{"contactfull", 250}, {"badqacc", 2}, {"other", 1}}));
  ASSERT_EQ(j.at("messages").size(), 3u);
  EXPECT_EQ(j.at("messages")[1].at("kind"), "badqacc");
  EXPECT_EQ(j.at("messages")[1].at("count"), 2);
  EXPECT_NE(j.at("messages")[1].at("text").get<std::string>().find("DOF 1"),
            std::string::npos);

  const nlohmann::json none = mujoco_warnings_json({}, {});
  EXPECT_EQ(none.at("count"), 0);
  EXPECT_TRUE(none.at("kinds").empty());
  EXPECT_TRUE(none.at("messages").empty());
}

// a clean run's summary says so
TEST(RunCase, ACleanRunHasNoWarnings) {
  const CaseResult r = run_case("case1", case1(), {"duration_s=0.2"}, "");
  EXPECT_EQ(r.summary.at("mujoco_warnings").at("count"), 0);
  EXPECT_EQ(r.summary.at("metrics").at("ticks"), 200);
}

// a hand a billion times stiffer than the scene's: the first physics step's
// qacc is beyond MuJoCo's 1e10, MuJoCo resets the state and would go on; the
// run stops with a PhysicsError instead (exit 1 on the command line)
TEST(RunCase, NonFinitePhysicsStopsTheRun) {
  sim::install_mujoco_handlers();
  try {
    run_case("case1", case1(), {"duration_s=0.2", "hand_k_pos_N_per_m=1e30"},
             "");
    FAIL() << "the run finished";
  } catch (const sim::PhysicsError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(case1() + ": physics went non-finite at t=0.001 s (q"),
              std::string::npos)
        << msg;
  }
}

// A run longer than kMaxKeptTicks streams every tick to trace.csv and keeps
// every k-th for its claims and figures, while its metrics still count every
// tick: memory stays flat however long the run. 61 s at 1 kHz: k = 2.
TEST(RunCase, ALongRunStreamsEveryTickAndKeepsEveryKth) {
  const std::string out = ::testing::TempDir() + "vmh_long_run";
  std::filesystem::remove_all(out);
  const CaseResult r =
      run_case("case1", case1(), {"duration_s=61", "script=hold"}, out);
  EXPECT_EQ(r.kept_every, 2);
  EXPECT_EQ(r.summary.at("measured_every_ticks"), 2);
  EXPECT_EQ(r.metrics.ticks, 61000);
  EXPECT_EQ(r.summary.at("metrics").at("ticks"), 61000);
  std::ifstream f(out + "/case1/trace.csv");
  ASSERT_TRUE(f.good());
  std::string line, last;
  std::int64_t lines = 0;
  while (std::getline(f, line)) {
    ++lines;
    last = line;
  }
  EXPECT_EQ(lines, 61001);  // the header and every tick
  EXPECT_EQ(last.rfind("60.999,", 0), 0u) << last;  // t_s of the last tick
  // nothing but the set: no temporary left beside it
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(out)) {
    ++entries;
    EXPECT_EQ(e.path().filename(), "case1");
  }
  EXPECT_EQ(entries, 1);
  std::filesystem::remove_all(out);
}

// A 20 s run is kept whole.
TEST(RunCase, AShortRunKeepsEveryTick) {
  const CaseResult r = run_case("case1", case1(), {"duration_s=2"}, "");
  EXPECT_EQ(r.kept_every, 1);
  EXPECT_EQ(r.metrics.ticks, 2000);
}

// The six cases as `run --all` runs them, with `overrides` and `options`.
std::vector<CaseJob> all_cases(const std::vector<std::string>& overrides,
                               const CaseRunOptions& options, int threads = 2) {
  std::vector<CaseJob> jobs;
  for (int n = 1; n <= 6; ++n) {
    CaseJob j;
    j.name = "case" + std::to_string(n);
    j.scene = std::string(VMH_MODELS_DIR) + "/cases/" + j.name + ".xml";
    jobs.push_back(j);
  }
  run_cases(&jobs, overrides, "", threads, "", {}, {}, options);
  for (const CaseJob& j : jobs) EXPECT_EQ(j.error, "") << j.name;
  return jobs;
}

// How far a claim's figure may move when the way it is simulated changes
// and nothing else (docs/testbed.md states them): 0.005 N (a tenth of the
// smallest threshold in newtons, on_path_no_force's 0.05 N), 0.5 deg (a
// quarter of off_path_force_toward_xv's 2 deg), and for the dimensionless
// fractions and ratios 5 % of the threshold's size, at least 0.05 (0.05 for
// the fractions judged at 0.95, 0.15 for force_grows_off_path's ratio
// judged at 3); and every verdict, prediction match and regime the same,
// on every side.
double figure_bound(const Claim& c) {
  if (c.unit == "N") return 0.005;
  if (c.unit == "deg") return 0.5;
  return 0.05 * std::max(1.0, std::abs(c.threshold));
}

// the largest move of any claim's figure on any side, in units of its
// bound; every verdict, match and regime checked equal
double compare_claims(const std::vector<CaseJob>& a,
                      const std::vector<CaseJob>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& ca = a[i].result.claims;
    const auto& cb = b[i].result.claims;
    EXPECT_EQ(ca.size(), cb.size()) << a[i].name;
    for (std::size_t k = 0; k < std::min(ca.size(), cb.size()); ++k) {
      const Claim& x = ca[k];
      const Claim& y = cb[k];
      const std::string what = a[i].name + " " + x.name;
      EXPECT_EQ(x.pass, y.pass) << what;
      EXPECT_EQ(x.partial, y.partial) << what;
      EXPECT_EQ(x.sides.size(), y.sides.size()) << what;
      for (std::size_t s = 0; s < std::min(x.sides.size(), y.sides.size()); ++s) {
        const Claim::Side& p = x.sides[s];
        const Claim::Side& q = y.sides[s];
        const std::string where = what + " (" + p.where + ")";
        EXPECT_EQ(p.where, q.where) << where;
        EXPECT_EQ(p.pass, q.pass) << where;
        EXPECT_EQ(p.regime, q.regime) << where;
        EXPECT_EQ(p.matches_prediction, q.matches_prediction) << where;
        const double bound = figure_bound(x);
        EXPECT_NEAR(p.value, q.value, bound) << where;
        worst = std::max(worst, std::abs(p.value - q.value) / bound);
      }
    }
  }
  return worst;
}

// Fitted sides (thesis/side_runs.h) against every side simulated whole:
// the main runs are the same runs, so their metrics are equal; the claims
// on every side within the bounds.
TEST(RunCases, FittedSidesKeepTheFiguresOfFullSides) {
  CaseRunOptions full;
  full.sides = SideMode::kFull;
  const std::vector<CaseJob> a = all_cases({}, {});
  const std::vector<CaseJob> b = all_cases({}, full);
  const double worst = compare_claims(a, b);
  std::printf("largest move of a claim's figure: %.3f of its bound\n", worst);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].result.summary.at("metrics"), b[i].result.summary.at("metrics"));
    EXPECT_EQ(a[i].result.summary.at("sides").at("mode"), "fitted");
    EXPECT_EQ(b[i].result.summary.at("sides").at("mode"), "full");
    // each side of a fitted run covers less script than the whole, or the
    // whole where its claims read to the end (case 4's sweep)
    for (const auto& run : a[i].result.summary.at("sides").at("runs")) {
      EXPECT_LE(run.at("script_s").get<double>(), 20.0 + 1e-9);
      EXPECT_LE(run.at("physics_s").get<double>(),
                run.at("script_s").get<double>() + 1e-9);
      EXPECT_TRUE(run.at("trace").is_null());
    }
  }
}

// The case scenes step with Euler at 1 ms (docs/testbed.md, "Physics
// step"); RK4 at the same step is 1000 times more accurate. The claims
// cannot tell them apart: on every side the same verdicts and figures
// within the bounds, and the main run's metrics within 0.01 mm (RMS path
// error), 0.2 mm (max), 0.005 N (mean and RMS force), 0.05 N (the largest
// force of a run: one tick's transient, 1.5 % of the 3.3 N limit) and 0.5 s
// on the path.
TEST(RunCases, EulerKeepsTheFiguresOfRk4WithinTheBounds) {
  const std::vector<CaseJob> euler = all_cases({}, {});
  const std::vector<CaseJob> rk4 = all_cases({"integrator=rk4"}, {});
  EXPECT_EQ(euler[0].result.summary.at("physics").at("integrator"), "Euler");
  EXPECT_EQ(rk4[0].result.summary.at("physics").at("integrator"), "RK4");
  const double worst = compare_claims(euler, rk4);
  std::printf("largest move of a claim's figure: %.3f of its bound\n", worst);
  for (std::size_t i = 0; i < euler.size(); ++i) {
    const RunMetrics& e = euler[i].result.metrics;
    const RunMetrics& r = rk4[i].result.metrics;
    const std::string n = euler[i].name;
    EXPECT_NEAR(e.rms_path_error_mm, r.rms_path_error_mm, 0.01) << n;
    EXPECT_NEAR(e.max_path_error_mm, r.max_path_error_mm, 0.2) << n;
    EXPECT_NEAR(e.mean_force_N, r.mean_force_N, 0.005) << n;
    EXPECT_NEAR(e.rms_force_N, r.rms_force_N, 0.005) << n;
    EXPECT_NEAR(e.max_force_N, r.max_force_N, 0.05) << n;
    EXPECT_NEAR(e.time_on_path_s, r.time_on_path_s, 0.5) << n;
  }
}

// summary.json without what the wall clock decides
nlohmann::json without_wall_times(nlohmann::json j) {
  j.erase("wall_time_s");
  j.erase("realtime_factor");
  for (auto& run : j.at("sides").at("runs")) run.erase("wall_time_s");
  return j;
}

// Every run of every case is taken from one pool by whichever thread is
// free; what is measured and written does not depend on which thread ran
// what, nor on how many there were: one thread and three give the same
// summaries, claims and sides in the same order.
TEST(RunCases, TheOutputsDoNotDependOnTheThreads) {
  const std::vector<CaseJob> one = all_cases({"duration_s=8"}, {}, 1);
  const std::vector<CaseJob> three = all_cases({"duration_s=8"}, {}, 3);
  ASSERT_EQ(one.size(), three.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].name, three[i].name);
    EXPECT_EQ(without_wall_times(one[i].result.summary),
              without_wall_times(three[i].result.summary))
        << one[i].name;
  }
}

// With --trace-sides each side writes its own trace beside trace.csv, and
// the summary names it.
TEST(RunCase, TraceSidesWritesOneTracePerSide) {
  const std::string out = ::testing::TempDir() + "vmh_trace_sides";
  std::filesystem::remove_all(out);
  CaseRunOptions o;
  o.trace_sides = true;
  const CaseResult r = run_case("case1", case1(), {}, out, "", {}, o);
  const auto& runs = r.summary.at("sides").at("runs");
  ASSERT_EQ(runs.size(), 4u);  // mirrored, below and its mirror, near the path
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const std::string file = "trace_side_" + std::to_string(i + 1) + ".csv";
    EXPECT_EQ(runs[i].at("trace"), file);
    std::ifstream f(out + "/case1/" + file);
    ASSERT_TRUE(f.good()) << file;
    std::string line;
    std::int64_t lines = 0;
    while (std::getline(f, line)) ++lines;
    EXPECT_EQ(lines, runs[i].at("ticks").get<std::int64_t>() + 1) << file;
  }
  std::filesystem::remove_all(out);
}

// The space check before any simulation: a bound on trace.csv's size (16
// bytes a column) and a tenth more, against what the disk has.
TEST(TraceFits, RefusesATraceTheDiskCannotHoldNamingBoth) {
  EXPECT_DOUBLE_EQ(runtime::trace_bytes_bound(20000, 55), 20000.0 * 55 * 16);
  EXPECT_NO_THROW(check_trace_fits("out", 20000, 55, 20000u * 55u * 16u * 2u));
  try {
    check_trace_fits("/full/disk", 3600000, 55, 1000000000u);
    FAIL() << "a 3.5 GB trace was let onto a 1 GB disk";
  } catch (const sim::SimError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'/full/disk'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("3600000 ticks"), std::string::npos) << msg;
    EXPECT_NE(msg.find("3.48e+03 MB"), std::string::npos) << msg;
    EXPECT_NE(msg.find("1e+03 MB free"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace vmh::thesis
