// bringup/compare_replay: `hw run`-like recordings written from the
// closed loop's own ticks (at the trace's %.9g, with a sensor fault that
// makes the guard refuse readings), replayed by a fresh controller; a gain
// changed after the fact must show, at the first row that carries a force.
#include "bringup/compare_replay.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/closed_loop.h"

namespace vmh::bringup {
namespace {

const std::string kReplayScene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";

double printed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return std::stod(buf);
}

// A hw run trace of `scene` under `overrides` for duration_s, as
// hw_session's format_row writes it: angles NaN on a failed read, the
// commanded torque zero when the tick was zeroed. meta holds what hw run's
// meta holds (verb, case, scene).
Recording run_recording(const std::vector<std::string>& overrides,
                        double duration_s) {
  std::vector<std::string> sets = overrides;
  sets.push_back("duration_s=" + std::to_string(duration_s));
  sim::ClosedLoop loop(kReplayScene, sets);
  Recording r;
  r.dir = "synthetic-run";
  r.verb = "hw run";
  r.meta = {{"verb", r.verb}, {"case", "case1"}, {"scene", kReplayScene}};
  const char* xyz[] = {"x", "y", "z"};
  TickRecord row;
  while (!loop.finished()) {
    loop.tick(&row);
    const bool ok = row.servo.read == DeviceError::kOk;
    r.num["t_s"].push_back(printed(row.t_s));
    for (int i = 0; i < 6; ++i) {
      r.num["q" + std::to_string(i + 1) + "_rad"].push_back(
          ok ? printed(row.q_dh[i]) : std::nan(""));
    }
    for (int i = 0; i < 3; ++i) {
      r.num["e_" + std::to_string(i + 1) + "_mm"].push_back(
          printed(row.out.e[i]));
      r.num[std::string("F_") + xyz[i] + "_N"].push_back(
          printed(row.out.force_device_N[i]));
      const double tau = row.servo.zeroed ? 0.0 : row.out.tau_motor_Nm[i];
      r.num["tau_" + std::to_string(i + 1) + "_Nm"].push_back(printed(tau));
      r.num["tau_sent_" + std::to_string(i + 1) + "_Nm"].push_back(
          printed(tau));
    }
    r.text["read_error"].push_back(device_error_name(row.servo.read));
    r.text["write_error"].push_back(device_error_name(row.servo.write));
    ++r.rows;
  }
  return r;
}

const CompareCheck* find(const CompareSection& s, const std::string& name) {
  for (const CompareCheck& c : s.checks) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

// a count slip on t2 that the device layer's guard refuses
const std::vector<std::string> kGlitch = {"fault=jump", "fault_joint=2",
                                          "fault_at_s=0.4"};

TEST(CompareReplay, ReproducesTheRecordedTorques) {
  const Recording r = run_recording(kGlitch, 0.8);
  ReplayOptions o;
  o.simulate = false;
  const CompareSection s = compare_closed_loop(r, o, "");
  const CompareCheck* c = find(s, "closed_loop.replay_torque_error_max");
  ASSERT_NE(c, nullptr);
  EXPECT_TRUE(c->pass) << c->value << " mNm: " << c->detail;
  RecordProperty("replay_torque_error_max_mNm", std::to_string(c->value));
  EXPECT_TRUE(s.faults.empty());
  // the refused readings were part of what was replayed
  EXPECT_GT(s.detail["replay"]["failed_reads"].get<long>(), 0);
  EXPECT_EQ(s.skipped.size(), 2u);
}

TEST(CompareReplay, AChangedGainFailsAtTheFirstRowWithAForce) {
  const Recording r = run_recording({}, 0.5);
  ReplayOptions o;
  o.simulate = false;
  o.overrides = {"k_pos_N_per_mm=0.55"};  // the scene says 0.5
  const CompareSection s = compare_closed_loop(r, o, "");
  const CompareCheck* c = find(s, "closed_loop.replay_torque_error_max");
  ASSERT_NE(c, nullptr);
  EXPECT_FALSE(c->pass);
  // a 10% gain change shows on the first row whose torque exceeds ten
  // times the threshold (a torque proportional to the gain moves by 10%)
  long expected = -1;
  for (std::size_t i = 0; i < r.rows && expected < 0; ++i) {
    for (int m = 1; m <= 3; ++m) {
      if (1e3 * std::abs(r.col("tau_" + std::to_string(m) + "_Nm")[i]) >
          10.0 * o.torque_error_max_mNm) {
        expected = static_cast<long>(i);
      }
    }
  }
  ASSERT_GE(expected, 0);
  ASSERT_TRUE(s.detail["replay"].contains("first_differing_row"));
  EXPECT_EQ(s.detail["replay"]["first_differing_row"]["row"].get<long>(),
            expected);
  EXPECT_NE(c->detail.find("row " + std::to_string(expected)),
            std::string::npos)
      << c->detail;
  ASSERT_EQ(s.faults.size(), 1u);
}

TEST(CompareReplay, UsesTheGainScaleTheRecordingNames) {
  Recording r = run_recording({"k_pos_N_per_mm=0.25"}, 0.4);
  r.meta["gain_scale"] = 0.5;  // hw run --gain-scale 0.5 on the scene's 0.5
  ReplayOptions o;
  o.simulate = false;
  const CompareSection s = compare_closed_loop(r, o, "");
  EXPECT_TRUE(find(s, "closed_loop.replay_torque_error_max")->pass);
  EXPECT_EQ(s.detail["gain_scale_from"], "meta.json");
  r.meta.erase("gain_scale");
  EXPECT_FALSE(
      find(compare_closed_loop(r, o, ""), "closed_loop.replay_torque_error_max")
          ->pass);
}

// A recording longer than the verbs keep (load_recording's window) is
// compared over its window, with the hand's script laid out as the session
// ran it: over the session's whole duration_s, from meta.json.
TEST(CompareReplay, AWindowIsComparedAsTheSessionRanIt) {
  Recording r = run_recording({}, 2.0);
  const std::size_t keep = r.rows / 2;
  r.rows_in_trace = r.rows;
  r.rows = keep;
  for (auto& [name, col] : r.num) col.resize(keep);
  for (auto& [name, col] : r.text) col.resize(keep);
  r.meta["session"] = {{"duration_s", 2.0}};
  ASSERT_TRUE(r.cut_to_window());
  const CompareSection s = compare_closed_loop(r, {}, "");
  for (const char* n : {"closed_loop.error_rms_ratio", "closed_loop.force_rms_ratio"}) {
    const CompareCheck* c = find(s, n);
    ASSERT_NE(c, nullptr) << n;
    // the same scene and script: the ratio is 1 up to the trace's printing
    EXPECT_NEAR(c->value, 1.0, 1e-3) << n << ": " << c->detail;
  }
  EXPECT_NEAR(s.detail["simulation"]["duration_s"].get<double>(),
              r.col("t_s")[keep - 1], 1e-12);
}

TEST(CompareReplay, SimulationMatchesItsOwnSceneAndNotAWeakerController) {
  const std::string dir = ::testing::TempDir() + "/compare_replay_fig";
  const CompareSection same =
      compare_closed_loop(run_recording({}, 2.0), {}, dir);
  for (const char* n :
       {"closed_loop.error_rms_ratio", "closed_loop.force_rms_ratio"}) {
    const CompareCheck* c = find(same, n);
    ASSERT_NE(c, nullptr) << n;
    EXPECT_TRUE(c->pass) << n << " " << c->value;
    // the same physics and controller: the same statistics
    EXPECT_NEAR(c->value, 1.0, 0.05) << n;
  }
  ASSERT_EQ(same.figures.size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(same.figures[0]));

  // recorded with a tenth of the stiffness, compared with the scene's
  ReplayOptions o;
  const Recording weak = run_recording({"k_pos_N_per_mm=0.05"}, 2.0);
  const CompareSection s = compare_closed_loop(weak, o, "");
  // the hand follows its script whatever the controller: a tenth of the
  // stiffness pushes it far less hard
  const CompareCheck* f = find(s, "closed_loop.force_rms_ratio");
  ASSERT_NE(f, nullptr);
  EXPECT_FALSE(f->pass) << f->value;
  EXPECT_LT(f->value, 0.5);
  EXPECT_FALSE(s.faults.empty());
}

TEST(CompareReplay, SkipsWhatIsNotAHwRunAndNamesBadOptions) {
  Recording r = run_recording({}, 0.1);
  r.verb = "hw record";
  const CompareSection s = compare_closed_loop(r, {}, "");
  EXPECT_TRUE(s.checks.empty());
  ASSERT_EQ(s.skipped.size(), 3u);
  EXPECT_NE(s.skipped[0].reason.find("not a hw run"), std::string::npos);
  ReplayOptions o;
  o.ratio_max = 0.1;
  try {
    compare_closed_loop(r, o, "");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ratio_max"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace vmh::bringup
