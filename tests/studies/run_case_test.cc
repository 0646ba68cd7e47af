// studies/run_case.h: one case run to its end. What `run` writes is checked
// by tests/cli/run_test.cc; here, what the library does with MuJoCo's
// warnings and with a physics state gone bad.
#include "studies/run_case.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
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

}  // namespace
}  // namespace vmh::studies
