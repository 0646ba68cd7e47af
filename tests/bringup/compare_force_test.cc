// bringup/compare_force: motor-test recordings synthesized from the
// closed loop's own device stepped directly (not ResponseSimulator), with a
// fault seeded in the truth the way the emulator would have it, and the
// analysis asked to name it; and the force mapping against a Jacobian
// found by finite differences of the FK.
#include "bringup/compare_force.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/closed_loop.h"
#include "sim/emulator_hand.h"
#include "tests/support/constants.h"
#include "tests/support/read_file.h"

namespace vmh::bringup {
namespace {

// the synthetic recordings apply each command one tick after it is written
// (the emulator applies it within the same period: its baseline is 0 ms)
ForceOptions synthetic_options() {
  ForceOptions o;
  o.lag_baseline_ms = 1.0;
  return o;
}

const std::string kForceScene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
// device angles (rad), a pose in the middle of the workspace
const Joints kForceQ0 = (Joints() << 0.1, 0.3, 0.2, 0.1, 0.3, -0.2).finished();
using vmh::testing::kPi;

// What is true of the device that recorded the test
struct Truth {
  sim::OmniModelEdit edit;    // the Omni's wiring (motor3_relative)
  double torque_scale = 1.0;  // units mistaken
  Vec3 motor_sign = Vec3::Ones();
  double reading_delay_s = 0.0;  // readings late
  ReadingMap map;                // reported = map.reported_from_true(true)
  // ticks from a command's write to the motors (the emulator: about one)
  int command_lag_ticks = 1;
};

double quantize(double v, double counts_per_rev) {
  const double step = 2.0 * kPi / counts_per_rev;
  return step * std::round(v / step);
}

// A `hw motor-test` trace: quiet, then `torque_Nm` on `motor` for pulse_ms,
// then quiet. The command written at a tick reaches the device at the next
// (as the emulator's threads do), the ticks jitter by a physics step, and
// one reading before the pulse fails.
Recording motor_test(int motor, double torque_Nm, double pulse_ms,
                     const Truth& truth) {
  sim::ClosedLoop loop(kForceScene, {}, sim::omni_model_hook("", truth.edit));
  const mjModel* m = loop.model();
  mjData* d = loop.data();
  const Joints q_dh0 = device_to_dh_joints(kForceQ0);
  for (int i = 0; i < 6; ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, sim::kOmniJoints[i]);
    d->qpos[m->jnt_qposadr[j]] = q_dh0[i];
    d->qvel[m->jnt_dofadr[j]] = 0.0;
  }
  mj_forward(m, d);
  sim::EmulatorHand hand(&loop);
  sim::SimDevice& dev = loop.device();

  Recording r;
  r.dir = "synthetic-motor" + std::to_string(motor);
  r.verb = "hw motor-test";
  r.meta = {
      {"verb", r.verb},
      {"motor", motor},
      {"torque_asked_mNm", 1e3 * torque_Nm},
      {"pulse_ms", pulse_ms},
      {"emulator", {{"scene", kForceScene}, {"hand", "none"}, {"model", nullptr}}}};
  const double h = m->opt.timestep;
  const double pulse_start_s = 0.08;
  std::vector<double> hist_t;
  std::vector<Joints> hist_q;
  std::vector<Vec3> pending(static_cast<std::size_t>(truth.command_lag_ticks),
                            Vec3::Zero());
  double t = 0.0;
  for (int k = 0; t < pulse_start_s + 1e-3 * pulse_ms + 0.1; ++k) {
    hist_t.push_back(t);
    hist_q.push_back(dh_to_device_joints(dev.true_q_dh()));
    // the reading reading_delay_s ago, linearly between the ticks
    const double t_read = std::max(0.0, t - truth.reading_delay_s);
    std::size_t a = 0;
    while (a + 1 < hist_t.size() && hist_t[a + 1] <= t_read) ++a;
    const std::size_t b = std::min(a + 1, hist_t.size() - 1);
    const double w =
        b > a ? (t_read - hist_t[a]) / (hist_t[b] - hist_t[a]) : 0.0;
    Joints q =
        truth.map.reported_from_true((1 - w) * hist_q[a] + w * hist_q[b]);
    for (int i = 0; i < 3; ++i) q[i] = quantize(q[i], 15000.0);
    for (int i = 3; i < 6; ++i) q[i] = quantize(q[i], 4096.0);
    const bool failed = k == 30;
    Vec3 tau = Vec3::Zero();
    if (t >= pulse_start_s && t < pulse_start_s + 1e-3 * pulse_ms && !failed) {
      tau[motor - 1] = torque_Nm;
    }
    r.num["t_s"].push_back(t);
    const Joints q_dh = device_to_dh_joints(q);
    for (int i = 0; i < 6; ++i) {
      r.num["q" + std::to_string(i + 1) + "_rad"].push_back(
          failed ? std::nan("") : q_dh[i]);
    }
    for (int i = 0; i < 3; ++i) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.9g", tau[i]);
      r.num["tau_sent_" + std::to_string(i + 1) + "_Nm"].push_back(
          std::stod(buf));
    }
    r.text["read_error"].push_back(failed ? "timeout" : "ok");
    ++r.rows;
    // last tick's command reaches the motors now, as the device has it
    pending.push_back(tau);
    dev.write_motor_torques(truth.torque_scale *
                            pending.front().cwiseProduct(truth.motor_sign));
    pending.erase(pending.begin());
    const int n =
        loop.substeps() + (k % 7 == 3 ? 1 : 0) - (k % 11 == 5 ? 1 : 0);
    for (int i = 0; i < n; ++i) {
      hand.let_go();
      mj_step(m, d);
    }
    t += n * h;
  }
  for (const auto& [name, v] : r.num) r.columns.push_back(name);
  r.columns.push_back("read_error");
  return r;
}

std::vector<std::string> fault_names(const CompareSection& s) {
  std::vector<std::string> out;
  for (const SuspectedFault& f : s.faults) out.push_back(f.name);
  return out;
}

std::string describe(const CompareSection& s) {
  std::string out;
  for (const CompareCheck& c : s.checks) {
    out += c.name + "=" + std::to_string(c.value) +
           (c.pass ? " pass; " : " FAIL; ");
  }
  for (const SuspectedFault& f : s.faults)
    out += "fault " + f.name + ": " + f.evidence + "; ";
  return out;
}

void expect_all_pass(const CompareSection& s) {
  ASSERT_EQ(s.checks.size(), 3u) << describe(s);
  for (const CompareCheck& c : s.checks) EXPECT_TRUE(c.pass) << describe(s);
  EXPECT_TRUE(s.faults.empty()) << describe(s);
}

const double kTorque_Nm[3] = {0.12, 0.2, 0.12};

TEST(CompareForce, CleanRecordingsPassOnEveryMotor) {
  for (int motor = 1; motor <= 3; ++motor) {
    const Recording r = motor_test(motor, kTorque_Nm[motor - 1], 40.0, {});
    const CompareSection s = compare_force_direction(r, {}, synthetic_options(), "");
    SCOPED_TRACE("motor " + std::to_string(motor));
    expect_all_pass(s);
    EXPECT_EQ(s.checks[0].name,
              "force_direction.motor" + std::to_string(motor) + "_angle");
  }
}

TEST(CompareForce, ASlowerCleanDeviceStillPasses) {
  // the emulator's threads may apply a command two ticks after its write
  Truth t;
  t.command_lag_ticks = 2;
  expect_all_pass(
      compare_force_direction(motor_test(2, 0.2, 40.0, t), {}, synthetic_options(), ""));
}

TEST(CompareForce, NamesAFlippedMotor) {
  for (int motor : {1, 3}) {
    Truth t;
    t.motor_sign[motor - 1] = -1.0;
    const CompareSection s = compare_force_direction(
        motor_test(motor, kTorque_Nm[motor - 1], 40.0, t), {}, synthetic_options(), "");
    EXPECT_EQ(
        fault_names(s),
        std::vector<std::string>{"motor" + std::to_string(motor) + "_sign"})
        << describe(s);
    EXPECT_GT(s.checks[0].value, 90.0) << "a reversed motor pushes backwards";
  }
}

TEST(CompareForce, NamesMotor3OnTheRelativeAngle) {
  Truth t;
  t.edit.motor3_relative = true;
  const CompareSection s =
      compare_force_direction(motor_test(3, 0.12, 40.0, t), {}, synthetic_options(), "");
  EXPECT_EQ(fault_names(s), std::vector<std::string>{"motor3_relative"})
      << describe(s);
}

TEST(CompareForce, NamesTorqueUnits) {
  Truth big;
  big.torque_scale = 1000.0;
  CompareSection s =
      compare_force_direction(motor_test(2, 0.05, 40.0, big), {}, synthetic_options(), "");
  EXPECT_EQ(fault_names(s), std::vector<std::string>{"torque_units_Nm"})
      << describe(s);
  Truth small;
  small.torque_scale = 0.001;
  s = compare_force_direction(motor_test(1, 0.12, 40.0, small), {}, synthetic_options(), "");
  EXPECT_EQ(fault_names(s), std::vector<std::string>{"torque_units_mNm"})
      << describe(s);
}

TEST(CompareForce, NamesLateReadings) {
  Truth t;
  t.reading_delay_s = 0.005;
  const CompareSection s =
      compare_force_direction(motor_test(2, 0.2, 40.0, t), {}, synthetic_options(), "");
  EXPECT_EQ(fault_names(s), std::vector<std::string>{"delay_5ms"})
      << describe(s);
  ASSERT_EQ(s.checks.size(), 3u);
  EXPECT_FALSE(s.checks[2].pass);
  // the truth: 5 ms on top of the clean 1 ms, within the search's step
  EXPECT_NEAR(s.checks[2].value, 6.0, 1.0);
}

TEST(CompareForce, ReadsThroughTheReadingMap) {
  Truth t;
  t.map.sign[0] = -1.0;
  t.map.name = "joint1_sign";
  const Recording r = motor_test(1, 0.12, 40.0, t);
  // read as reported, joint 1's reading looks like a reversed motor
  const CompareSection raw = compare_force_direction(r, {}, synthetic_options(), "");
  EXPECT_EQ(fault_names(raw), std::vector<std::string>{"motor1_sign"})
      << describe(raw);
  // read through the map kinematics found, the motor is fine
  const CompareSection mapped = compare_force_direction(r, t.map, synthetic_options(), "");
  expect_all_pass(mapped);
}

TEST(CompareForce, NoPulseSkipsWithAReason) {
  const Recording r = motor_test(1, 0.0, 40.0, {});
  const CompareSection s = compare_force_direction(r, {}, synthetic_options(), "");
  EXPECT_TRUE(s.checks.empty());
  ASSERT_EQ(s.skipped.size(), 3u);
  EXPECT_NE(s.skipped[0].reason.find("no pulse"), std::string::npos)
      << s.skipped[0].reason;
}

TEST(CompareForce, APulseTheModelSaysCannotMoveTheArmJudgesNothing) {
  // 5 mN m on the shoulder does not overcome its friction
  const CompareSection s =
      compare_force_direction(motor_test(1, 0.005, 40.0, {}), {}, synthetic_options(), "");
  EXPECT_TRUE(s.checks.empty()) << describe(s);
  ASSERT_EQ(s.skipped.size(), 3u);
  EXPECT_NE(s.skipped[0].reason.find("joint limit"), std::string::npos);
  EXPECT_TRUE(s.faults.empty()) << describe(s);
}

TEST(CompareForce, BadOptionsAreNamed) {
  const Recording r = motor_test(1, 0.06, 10.0, {});
  ForceOptions o;
  o.gain_max = 0.1;
  try {
    compare_force_direction(r, {}, o, "");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gain_max"), std::string::npos)
        << e.what();
  }
  Recording bad = r;
  bad.meta["motor"] = 5;
  EXPECT_THROW(compare_force_direction(bad, {}, synthetic_options(), ""), std::invalid_argument);
}

TEST(CompareForce, WritesTheFigure) {
  const std::string dir = ::testing::TempDir() + "/compare_force_fig";
  const CompareSection s =
      compare_force_direction(motor_test(2, 0.12, 40.0, {}), {}, {}, dir);
  ASSERT_EQ(s.figures.size(), 1u);
  EXPECT_EQ(std::filesystem::path(s.figures[0]).filename(),
            "force_direction_motor2.svg");
  const std::string text = vmh::testing::read_file(s.figures[0]);
  EXPECT_NE(text.find("class=\"chart-grid\""), std::string::npos);
  EXPECT_TRUE(s.detail["history"].is_array());
  EXPECT_GT(s.detail["history"].size(), 10u);
}

// A `hw run`-like trace from the closed loop: the controller's force and
// motor torques, and a device Jacobian (linear rows mm/rad over device
// joints t1..t3) by central differences of the FK, not the controller's J_r
Recording run_with_jacobian(double column1_sign) {
  sim::ClosedLoop loop(kForceScene, {});
  const OmniParams omni;
  Recording r;
  r.dir = "synthetic-run";
  r.verb = "hw run";
  r.meta = {{"verb", r.verb}};
  TickRecord row;
  for (int k = 0; k < 3000; ++k) {
    loop.tick(&row);
    const Joints t = dh_to_device_joints(row.q_dh);
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
    for (int c = 0; c < 3; ++c) {
      Joints a = t, b = t;
      a[c] += 1e-6;
      b[c] -= 1e-6;
      const Vec3 pa = base_to_device_mm(
          omni, omni_fk(omni, device_to_dh_joints(a)).p_base_m);
      const Vec3 pb = base_to_device_mm(
          omni, omni_fk(omni, device_to_dh_joints(b)).p_base_m);
      J.block<3, 1>(0, c) = (c == 0 ? column1_sign : 1.0) * (pa - pb) / 2e-6;
    }
    r.num["t_s"].push_back(row.t_s);
    for (int i = 0; i < 6; ++i)
      r.num["q" + std::to_string(i + 1) + "_rad"].push_back(row.q_dh[i]);
    const char* xyz[] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      r.num[std::string("F_") + xyz[i] + "_N"].push_back(
          row.out.force_device_N[i]);
      r.num["tau_" + std::to_string(i + 1) + "_Nm"].push_back(
          row.out.tau_motor_Nm[i]);
      r.num["tau_sent_" + std::to_string(i + 1) + "_Nm"].push_back(
          row.out.tau_motor_Nm[i]);
    }
    for (int a = 0; a < 6; ++a) {
      for (int c = 0; c < 6; ++c) {
        r.num["dev_J_" + std::to_string(a + 1) + std::to_string(c + 1)]
            .push_back(J(a, c));
      }
    }
    r.text["read_error"].push_back("ok");
    ++r.rows;
  }
  return r;
}

TEST(CompareForceMapping, AgreesWithAnFkJacobianAndCatchesAFlippedColumn) {
  const CompareSection good = compare_force_mapping(run_with_jacobian(1.0));
  ASSERT_EQ(good.checks.size(), 1u)
      << (good.skipped.empty() ? "" : good.skipped[0].reason);
  EXPECT_TRUE(good.checks[0].pass) << good.checks[0].detail;
  EXPECT_LT(good.checks[0].value, 1.0);
  EXPECT_GT(good.detail["rows"].get<long>(), 50);
  EXPECT_TRUE(good.faults.empty());

  const CompareSection bad = compare_force_mapping(run_with_jacobian(-1.0));
  ASSERT_EQ(bad.checks.size(), 1u);
  EXPECT_FALSE(bad.checks[0].pass) << bad.checks[0].value;
  EXPECT_EQ(bad.faults.size(), 1u);
}

TEST(CompareForceMapping, SkipsWithoutTheDevicesJacobian) {
  Recording r = run_with_jacobian(1.0);
  for (auto it = r.num.begin(); it != r.num.end();) {
    it = it->first.rfind("dev_J_", 0) == 0 ? r.num.erase(it) : std::next(it);
  }
  const CompareSection s = compare_force_mapping(r);
  EXPECT_TRUE(s.checks.empty());
  ASSERT_EQ(s.skipped.size(), 1u);
  EXPECT_NE(s.skipped[0].reason.find("Jacobian"), std::string::npos);
  EXPECT_EQ(compare_force_mapping(motor_test(1, 0.12, 10.0, {})).skipped.size(),
            1u);
}

}  // namespace
}  // namespace vmh::bringup
