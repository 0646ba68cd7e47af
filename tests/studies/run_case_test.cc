// studies/run_case.h: one case run to its end. What `run` writes is checked
// by tests/cli/run_test.cc; here, what the library does with MuJoCo's
// warnings and with a physics state gone bad.
#include "runtime/trace_writer.h"
#include "studies/run_case.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/mujoco_messages.h"

namespace vmh::studies {
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
  const std::string out = testing::TempDir() + "vmh_long_run";
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
}  // namespace vmh::studies
