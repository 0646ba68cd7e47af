// `hw run` on the emulator in lockstep (thesis/hw_run.h) against the
// simulated closed loop behind the safety layer (`run --set
// safety_layer=1`): the same ticks, so the same metrics and the same claims
// to within the emulator's sensor path (raw counts and pot codes decoded
// back to angles, within 1e-15 rad of the sensor model's). The bound
// tested here is the one docs/hardware.md ("Two clocks") states; each case
// checks it on all of its claims. And lockstep is deterministic: two
// sessions give the same records to the last bit.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "runtime/backend_registry.h"
#include "runtime/session.h"
#include "sim/emulator_backend.h"
#include "thesis/claims.h"
#include "thesis/hw_run.h"
#include "tests/support/thesis_cases.h"

namespace vmh::thesis {
namespace {

using vmh::testing::thesis_case_scene;

// the bound docs/hardware.md states for a claim's value, relative to the
// larger of the two (or absolute below 1e-6)
constexpr double kClaimBound = 1e-6;

runtime::BackendRegistry& registry() {
  static runtime::BackendRegistry r = [] {
    runtime::BackendRegistry reg;
    sim::register_backends(&reg);
    return reg;
  }();
  return r;
}

runtime::OpenedDevice open_emulator(const std::string& scene,
                                    const std::vector<std::string>& sets) {
  runtime::OpenRequest rq;
  rq.defaults["hand"] = "case";
  rq.scene_sets = sets;
  rq.load_calibration = false;
  rq.lockstep = true;
  return registry().open("emulator:" + scene, rq);
}

runtime::SessionOptions lockstep_session() {
  runtime::SessionOptions so;
  so.servo.lockstep = true;
  so.progress = false;
  return so;
}

// the simulated loop behind the safety layer, to its end
std::vector<TickRecord> run_loop(sim::ClosedLoop* loop, RunMetrics* metrics) {
  if (auto ref = reference_params(loop->config().thesis_case,
                                  loop->controller_params())) {
    loop->set_reference(*ref);
  }
  MetricsAccumulator acc(loop->the_case());
  std::vector<TickRecord> rows;
  TickRecord row;
  while (!loop->finished()) {
    loop->tick(&row);
    acc.add(row);
    rows.push_back(row);
  }
  *metrics = acc.result();
  return rows;
}

bool close(double a, double b) {
  return std::abs(a - b) <=
         kClaimBound * std::max({1e-6, std::abs(a), std::abs(b)});
}

class HwRunLockstep : public vmh::testing::ThesisCaseTest {};

TEST_P(HwRunLockstep, MatchesTheSimulatedLoopBehindTheSafetyLayer) {
  const int n = GetParam();
  const std::string scene = thesis_case_scene(n);
  const std::vector<std::string> sets = {"duration_s=8"};

  HwRunCase hw(scene, sets, "", 1.0);
  runtime::OpenedDevice dev = open_emulator(scene, sets);
  runtime::SessionResult session;
  const Json summary = hw.run(&dev, lockstep_session(), &session);
  ASSERT_EQ(session.clock, "lockstep");
  ASSERT_EQ(session.stop_reason, "duration");
  ASSERT_TRUE(summary.value("claims_judged", false)) << summary.dump();

  std::vector<std::string> with_safety = sets;
  with_safety.push_back("safety_layer=1");
  sim::ClosedLoop loop(scene, with_safety);
  RunMetrics m;
  const std::vector<TickRecord> rows = run_loop(&loop, &m);
  ASSERT_EQ(session.ticks, static_cast<long>(rows.size()));
  const std::vector<Claim> claims =
      evaluate_claims(loop.config().thesis_case, rows, loop.the_case());

  const Json& hm = summary.at("metrics");
  EXPECT_EQ(hm.at("ticks").get<int>(), m.ticks);
  EXPECT_TRUE(close(hm.at("rms_path_error_mm").get<double>(), m.rms_path_error_mm))
      << hm.at("rms_path_error_mm") << " vs " << m.rms_path_error_mm;
  EXPECT_TRUE(close(hm.at("max_force_N").get<double>(), m.max_force_N));
  const Json& hc = summary.at("claims");
  ASSERT_EQ(hc.size(), claims.size());
  ASSERT_FALSE(claims.empty());
  for (std::size_t i = 0; i < claims.size(); ++i) {
    EXPECT_EQ(hc[i].at("name").get<std::string>(), claims[i].name);
    EXPECT_EQ(hc[i].at("pass").get<bool>(), claims[i].pass) << claims[i].name;
    EXPECT_TRUE(close(hc[i].at("value").get<double>(), claims[i].value))
        << "case " << n << " " << claims[i].name << ": hw run "
        << hc[i].at("value") << ", run " << claims[i].value;
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, HwRunLockstep, ::testing::Range(1, 7));

// the same lockstep session twice: every record the same to the last bit
TEST(HwRunLockstepDeterminism, TwoSessionsGiveTheSameRecords) {
  const std::string scene = thesis_case_scene(2);
  std::vector<std::vector<double>> runs[2];
  for (auto& run : runs) {
    runtime::OpenedDevice dev = open_emulator(scene, {"duration_s=2"});
    runtime::SessionOptions so = lockstep_session();
    HwRunCase hw(scene, {"duration_s=2"}, "", 1.0);
    hw.configure(&so);
    so.on_record = [&run](const TickRecord& r) {
      run.push_back({r.t_s, r.q_dh[0], r.q_dh[4], r.tau_sent_Nm[1],
                     r.out.force_device_N[2], r.p_true_mm[0], r.energy_motor_J});
    };
    const runtime::SessionResult res = runtime::run_session(&dev, so);
    ASSERT_EQ(res.stop_reason, "duration");
  }
  ASSERT_EQ(runs[0].size(), 2000u);
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (std::size_t k = 0; k < runs[0].size(); ++k) {
    ASSERT_EQ(runs[0][k], runs[1][k]) << "record " << k;
  }
}

}  // namespace
}  // namespace vmh::thesis
