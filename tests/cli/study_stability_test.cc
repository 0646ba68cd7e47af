// `vmhaptics study stability`, as a user runs it: the JSON's keys and
// numbers, the files --out and --map write, and the errors for bad input
// (named, one line, exit 2). h = T/100 keeps each run short.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using vmh::testing::run;

fs::path stability_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_stability_", name);
}


const char* const kBase = "study stability --mass 1 --damping 2 --servo-period 0.001 ";

TEST(StudyStabilityCli, PrintsKcritAgainstTheory) {
  const auto r = run(std::string(kBase) +
                     "--virtual-damping 1 --physics-step 1e-5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("study"), "stability");
  for (const char* k :
       {"k_crit_N_per_m", "k_stable_N_per_m", "k_unstable_N_per_m",
        "k_bound_gil_N_per_m", "k_crit_exact_discrete_N_per_m",
        "k_crit_mujoco_euler_discrete_N_per_m", "k_passivity_N_per_m",
        "rel_error_vs_gil", "rel_error_vs_exact_discrete",
        "rel_error_vs_mujoco_euler_discrete", "bT_over_m", "BT_over_m",
        "iterations", "wall_time_s", "bound", "inputs", "tolerance"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  const auto& in = j.at("inputs");
  EXPECT_DOUBLE_EQ(in.at("mass_kg").get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(in.at("damping_Ns_per_m").get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(in.at("servo_period_s").get<double>(), 1e-3);
  EXPECT_DOUBLE_EQ(in.at("virtual_damping_Ns_per_m").get<double>(), 1.0);
  EXPECT_EQ(in.at("delay_ticks"), 0);
  EXPECT_EQ(in.at("steps_per_tick"), 100);
  // 2 (b + B)/T = 6000 N/m; the simulation within 5% (in fact ~1%)
  EXPECT_DOUBLE_EQ(j.at("k_bound_gil_N_per_m").get<double>(), 6000.0);
  EXPECT_DOUBLE_EQ(j.at("bound").at("k_N_per_m").get<double>(), 6000.0);
  const double k = j.at("k_crit_N_per_m").get<double>();
  EXPECT_NEAR(k / 6000.0, 1.0, 0.05);
  EXPECT_NEAR(j.at("rel_error_vs_gil").get<double>(), k / 6000.0 - 1.0, 1e-12);
  EXPECT_LE(j.at("k_stable_N_per_m").get<double>(), k);
  EXPECT_GE(j.at("k_unstable_N_per_m").get<double>(), k);
  EXPECT_LT(std::abs(j.at("rel_error_vs_mujoco_euler_discrete").get<double>()),
            1e-4);
  EXPECT_DOUBLE_EQ(j.at("k_passivity_N_per_m").get<double>(), 2000.0);
  EXPECT_GE(j.at("iterations").at("sim_runs").get<int>(), 3);
}

TEST(StudyStabilityCli, OneTickDelayAndOutputs) {
  const fs::path out = stability_dir("delay");
  const auto r = run(std::string(kBase) +
                     "--delay-ticks 1 --physics-step 1e-5 --out " +
                     out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const double bound = 2.0 / 1.5e-3;
  EXPECT_NEAR(j.at("k_bound_gil_N_per_m").get<double>(), bound, 1e-9);
  EXPECT_NEAR(j.at("k_crit_N_per_m").get<double>() / bound, 1.0, 0.05);
  EXPECT_DOUBLE_EQ(j.at("inputs").at("delay_s").get<double>(), 1e-3);
  const std::string csv = vmh::testing::read_file(out / "stability_bisection.csv");
  EXPECT_EQ(csv.rfind("run,k_N_per_m,stable,diverged,growth_rate_per_s,"
                      "early_peak_m,late_peak_m,ticks\n",
                      0),
            0u);
  std::size_t rows = 0;
  for (char c : csv) rows += c == '\n' ? 1 : 0;
  EXPECT_EQ(rows, 1u + j.at("iterations").at("sim_runs").get<std::size_t>());
  EXPECT_EQ(vmh::testing::read_file(out / "stability_bisection.svg").rfind("<svg", 0), 0u);
  EXPECT_EQ(j.at("outputs").size(), 2u);
}

TEST(StudyStabilityCli, MapWritesTableAndChart) {
  const fs::path out = stability_dir("map");
  const auto r = run(std::string(kBase) +
                     "--map --map-points 2 --map-b-max 4 --delay-ticks 1 "
                     "--physics-step 2e-5 --jobs 2 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("mode"), "map");
  EXPECT_EQ(j.at("points"), 2);
  EXPECT_EQ(j.at("virtual_damping_Ns_per_m"), nlohmann::json({0.0, 4.0}));
  EXPECT_EQ(j.at("delay_ticks"), nlohmann::json({1}));
  EXPECT_LT(j.at("max_abs_rel_error_sim_vs_exact").get<double>(), 0.01);
  const std::string csv = vmh::testing::read_file(out / "stability_map.csv");
  EXPECT_EQ(csv.rfind("virtual_damping_Ns_per_m,delay_ticks,"
                      "k_crit_sim_N_per_m,",
                      0),
            0u);
  EXPECT_NE(csv.find("\n4,1,"), std::string::npos);
  const std::string svg = vmh::testing::read_file(out / "stability_map.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("simulated, n = 1"), std::string::npos);
}

// (arguments, text the one-line error must hold)
TEST(StudyStabilityCli, BadInputIsNamedAndExitsTwo) {
  const std::string ok = kBase;
  const std::pair<std::string, std::string> cases[] = {
      {"study stability --damping 2 --servo-period 0.001", "--mass"},
      {"study stability --mass 1 --damping 2 --servo-period 0.001x",
       "--servo-period"},
      {"study stability --mass -1 --damping 2 --servo-period 0.001", "--mass"},
      {"study stability --mass 1 --damping -2 --servo-period 0.001",
       "--damping"},
      {"study stability --mass 1 --damping 2 --servo-period 0", "--servo-period"},
      // issue 17: 1e-12 s ran for ever, 1e308 s printed K_crit = 0
      {"study stability --mass 1 --damping 2 --servo-period 1e-12",
       "--servo-period"},
      {"study stability --mass 1 --damping 2 --servo-period 1e308",
       "--servo-period"},
      {ok + "--jobs=-5", "--jobs"},
      {ok + "--virtual-damping -1", "--virtual-damping"},
      {ok + "--delay-ticks 99", "--delay-ticks"},
      {ok + "--physics-step 0.0003", "--physics-step"},
      {ok + "--physics-step 0.002", "--physics-step"},
      {ok + "--physics-step -1e-5", "--physics-step"},
      {"study stability --mass 1 --damping 0 --servo-period 0.001",
       "--damping, --virtual-damping"},
      {ok + "--tolerance 0.5", "--tolerance"},
      {ok + "--map", "--map"},
      {ok + "--map --virtual-damping 1 --out /tmp/x", "--virtual-damping"},
      {ok + "--map --map-points 1 --out /tmp/x", "--map-points"},
  };
  for (const auto& [args, option] : cases) {
    const auto r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.out << r.err;
    EXPECT_EQ(r.out, "") << args;
    EXPECT_NE(r.err.find(option), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << ": " << r.err;
  }
}

}  // namespace
