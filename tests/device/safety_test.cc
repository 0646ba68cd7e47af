// device/safety.h against a scripted device: every limit triggers and
// recovers, with the numbers checked against closed forms (the ramp's value
// at k ticks, the impulse limit's ramp of a step, the thermal model's times
// to warn, cut and resume from its exponential solution), the clamps keep
// the force's direction under a Jacobian computed here by finite differences
// of omni_fk, every fault puts zero torque on the device, and the servo path
// allocates nothing.
#include "device/safety.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "controller/controller.h"
#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/servo_tick.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/scripted_device.h"

namespace vmh {
namespace {

using testing::ScriptedDevice;

static_assert(noexcept(std::declval<SafetyLayer&>().read_joints(nullptr)));
static_assert(noexcept(
    std::declval<SafetyLayer&>().write_motor_torques(std::declval<const Vec3&>())));
static_assert(noexcept(std::declval<SafetyLayer&>().service_watchdog(0.0)));
static_assert(noexcept(std::declval<ServoWatchdog&>().kick(0.0)));
static_assert(noexcept(std::declval<const ServoWatchdog&>().expired(0.0)));

constexpr double kDt = 1e-3;

// Every limit but the one under test out of the way: no ramp, no impulse
// limit, a motor that does not warm, speeds no hand reaches.
SafetyParams quiet() {
  SafetyParams p;
  p.servo_period_s = kDt;
  p.ramp_s = 0.0;
  p.max_force_step_N = 1e6;
  p.thermal_time_constant_s = 1e9;
  p.max_tip_speed_m_s = 1e3;
  p.resume_tip_speed_m_s = 5e2;
  p.max_joint_speed_rad_s = 1e4;
  p.resume_joint_speed_rad_s = 5e3;
  return p;
}

// a pose well inside the workspace, away from singularities (DH convention)
Joints pose_dh() {
  Joints q;
  q << 0.2, 0.3, 0.4, 0.1, -0.2, 0.3;
  return q;
}

// J_v by central differences of omni_fk: independent of omni_jacobian
Mat3 fd_jacobian(const Joints& q_dh) {
  const OmniParams omni;
  const double h = 1e-6;
  Mat3 J;
  for (int j = 0; j < 3; ++j) {
    Joints a = q_dh, b = q_dh;
    a[j] += h;
    b[j] -= h;
    J.col(j) = (omni_fk(omni, a).p_base_m - omni_fk(omni, b).p_base_m) / (2 * h);
  }
  return J;
}

// motor torques that make device-frame force F_dev at the wrist centre
Vec3 torque_for_force(const Joints& q_dh, const Vec3& F_dev_N) {
  const Vec3 F_base = R_device_base().transpose() * F_dev_N;
  return dh_to_motor_torques(fd_jacobian(q_dh).transpose() * F_base);
}

// device-frame force that motor torques make at the wrist centre
Vec3 force_for_torque(const Joints& q_dh, const Vec3& tau_motor_Nm) {
  const Vec3 tau_dh = motor_to_dh_torques(tau_motor_Nm);
  return R_device_base() *
         fd_jacobian(q_dh).transpose().partialPivLu().solve(tau_dh);
}

double parallel_error(const Vec3& a, const Vec3& b) {
  return (a.normalized() - b.normalized()).norm();
}

struct Rig {
  explicit Rig(const SafetyParams& p = quiet()) : layer(&dev, p) {
    dev.q = dh_to_device_joints(pose_dh());
  }
  // one servo tick: read, then write the command; returns what reached the
  // device
  Vec3 tick(const Vec3& tau) {
    read_only();
    return write_only(tau);
  }
  void read_only() {
    Joints q;
    read = layer.read_joints(&q);
  }
  Vec3 write_only(const Vec3& tau) {
    write = layer.write_motor_torques(tau);
    return dev.written;
  }
  ScriptedDevice dev;
  SafetyLayer layer;
  DeviceError read = DeviceError::kOk;
  DeviceError write = DeviceError::kOk;
};

const Vec3 kSmall(0.01, -0.02, 0.015);  // N m, far under every limit

TEST(SafetyNames, EveryFlagHasItsOwnName) {
  std::set<std::string> names;
  for (int b = 0; b < kSafetyFlagCount; ++b) {
    const std::string n = safety_flag_name(1u << b);
    EXPECT_NE(n, "unknown") << "bit " << b;
    EXPECT_NE(n, "ok");
    names.insert(n);
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kSafetyFlagCount));
  EXPECT_STREQ(safety_flag_name(kSafetyOk), "ok");
  EXPECT_STREQ(safety_flag_name(kSafetyMotorWarm), "motor_warm");
  EXPECT_STREQ(safety_flag_name(kSafetyForceImpulseLimited),
               "force_impulse_limited");
  EXPECT_STREQ(safety_flag_name(1u << kSafetyFlagCount), "unknown");
  EXPECT_STREQ(safety_flag_name(kSafetyDocked | kSafetyCommLost), "unknown");
}

TEST(SafetyParams, DefaultsAreTheOmnisRatings) {
  const SafetyParams p;
  const OmniParams omni;
  EXPECT_NO_THROW(p.validate());
  EXPECT_EQ(p.max_force_N, omni.max_force_N);
  EXPECT_EQ(p.continuous_force_N, omni.continuous_force_N);
  EXPECT_EQ(p.motor_torque_limit_Nm, omni.motor_torque_limit_Nm);
  EXPECT_EQ(p.servo_period_s, 1e-3);
}

TEST(SafetyParams, EachBadFieldIsNamed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* field;
    void (*spoil)(SafetyParams*);
  };
  const Case cases[] = {
      {"servo_period_s", [](SafetyParams* p) { p->servo_period_s = 0.0; }},
      {"max_force_N", [](SafetyParams* p) { p->max_force_N = -1.0; }},
      {"motor_torque_limit_Nm",
       [](SafetyParams* p) { p->motor_torque_limit_Nm[1] = 0.0; }},
      {"singular_damping_m",
       [](SafetyParams* p) { p->singular_damping_m = -1e-3; }},
      {"ramp_s", [](SafetyParams* p) { p->ramp_s = -0.1; }},
      {"max_force_step_N", [](SafetyParams* p) { p->max_force_step_N = 0.0; }},
      {"max_tip_speed_m_s", [](SafetyParams* p) { p->max_tip_speed_m_s = 0.0; }},
      {"resume_tip_speed_m_s",
       [](SafetyParams* p) { p->resume_tip_speed_m_s = p->max_tip_speed_m_s; }},
      {"max_joint_speed_rad_s",
       [](SafetyParams* p) { p->max_joint_speed_rad_s = -2.0; }},
      {"resume_joint_speed_rad_s",
       [](SafetyParams* p) { p->resume_joint_speed_rad_s = 100.0; }},
      {"continuous_force_N", [](SafetyParams* p) { p->continuous_force_N = 0.0; }},
      {"thermal_time_constant_s",
       [](SafetyParams* p) { p->thermal_time_constant_s = 0.0; }},
      {"thermal_cut", [](SafetyParams* p) { p->thermal_cut = -1.0; }},
      {"thermal_warn", [](SafetyParams* p) { p->thermal_warn = 3.0; }},
      {"thermal_resume", [](SafetyParams* p) { p->thermal_resume = 2.0; }},
      {"derate_at_cut", [](SafetyParams* p) { p->derate_at_cut = 1.5; }},
      {"comm_lost_reads", [](SafetyParams* p) { p->comm_lost_reads = 0; }},
      {"comm_resume_reads", [](SafetyParams* p) { p->comm_resume_reads = 0; }},
      {"watchdog_periods", [](SafetyParams* p) { p->watchdog_periods = 0; }},
  };
  for (const Case& c : cases) {
    SafetyParams p;
    c.spoil(&p);
    try {
      p.validate();
      ADD_FAILURE() << c.field << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos)
          << e.what();
    }
    ScriptedDevice dev;
    EXPECT_THROW(SafetyLayer(&dev, p), std::invalid_argument) << c.field;
  }
  SafetyParams p;
  p.max_force_N = nan;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  EXPECT_THROW(SafetyLayer(nullptr, SafetyParams()), std::invalid_argument);
}

TEST(SafetyLayer, PassesWhatIsWithinEveryLimit) {
  Rig rig;
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(rig.tick(kSmall), kSmall);
    EXPECT_EQ(rig.read, DeviceError::kOk);
    EXPECT_EQ(rig.write, DeviceError::kOk);
    EXPECT_EQ(rig.layer.status(), kSafetyOk);
  }
}

TEST(SafetyLayer, ForceAtThePoseMatchesAFiniteDifferenceJacobian) {
  Rig rig;
  rig.tick(Vec3::Zero());
  const Vec3 tau(0.05, -0.08, 0.03);
  EXPECT_LT((rig.layer.force_device_N(tau) - force_for_torque(pose_dh(), tau))
                .norm(),
            1e-6);
}

TEST(SafetyLayer, TorqueClampScalesAllMotorsByOneFactor) {
  Rig rig;
  const Vec3 tau(0.5, 0.1, -0.05);  // motor 1 at 2.5x its 0.2 N m clamp
  const Vec3 out = rig.tick(tau);
  EXPECT_NEAR(out[0], 0.2, 1e-12);
  EXPECT_LT((out - tau * (0.2 / 0.5)).norm(), 1e-12);
  EXPECT_LT(parallel_error(force_for_torque(pose_dh(), out),
                           force_for_torque(pose_dh(), tau)),
            1e-9);
  EXPECT_TRUE(rig.layer.status() & kSafetyTorqueClamped);
  // recovers at once
  EXPECT_EQ(rig.tick(kSmall), kSmall);
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
}

TEST(SafetyLayer, ForceClampKeepsTheForceDirection) {
  SafetyParams p = quiet();
  p.max_force_N = 1.0;
  p.motor_torque_limit_Nm = {10.0, 10.0, 10.0};
  Rig rig(p);
  const Vec3 F(1.5, -2.0, 0.0);  // 2.5 N, device frame
  const Vec3 out = rig.tick(torque_for_force(pose_dh(), F));
  const Vec3 F_out = force_for_torque(pose_dh(), out);
  EXPECT_NEAR(F_out.norm(), 1.0, 1e-6);
  EXPECT_LT((F_out - F / 2.5).norm(), 1e-6);
  EXPECT_TRUE(rig.layer.status() & kSafetyForceClamped);
  EXPECT_FALSE(rig.layer.status() & kSafetyTorqueClamped);
  const Vec3 F_ok(0.3, 0.2, -0.4);
  const Vec3 tau_ok = torque_for_force(pose_dh(), F_ok);
  EXPECT_LT((rig.tick(tau_ok) - tau_ok).norm(), 1e-15);
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
}

TEST(SafetyLayer, RampRisesLinearlyAndRestartsAfterAFault) {
  SafetyParams p = quiet();
  p.ramp_s = 0.1;  // 100 ticks
  Rig rig(p);
  const Vec3 tau(0.1, 0.2, -0.1);
  for (int round = 0; round < 2; ++round) {
    for (int k = 0; k <= 120; ++k) {
      const Vec3 out = rig.tick(tau);
      const double s = std::min(1.0, k * kDt / 0.1);
      EXPECT_LT((out - s * tau).norm(), 1e-12) << "tick " << k;
      EXPECT_EQ((rig.layer.status() & kSafetyForceRamping) != 0, s < 1.0)
          << "tick " << k;
    }
    // a fault (docked for one tick) zeroes the torque and restarts the ramp
    rig.layer.set_inputs(true, false);
    EXPECT_EQ(rig.tick(tau), Vec3::Zero());
    EXPECT_TRUE(rig.layer.status() & kSafetyDocked);
    rig.layer.set_inputs(false, false);
  }
}

TEST(SafetyLayer, ForceOutputOffCutsAndTurningItOnRamps) {
  SafetyParams p = quiet();
  p.ramp_s = 0.01;
  Rig rig(p);
  for (int k = 0; k < 20; ++k) rig.tick(kSmall);
  EXPECT_EQ(rig.dev.written, kSmall);
  rig.layer.set_force_output(false);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
  EXPECT_EQ(rig.layer.status(), kSafetyForceOutputOff);
  rig.layer.set_force_output(true);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());  // k = 0 of the ramp
  EXPECT_LT((rig.tick(kSmall) - 0.1 * kSmall).norm(), 1e-15);
}

TEST(SafetyLayer, ImpulseLimitTurnsAStepIntoARamp) {
  SafetyParams p = quiet();
  p.max_force_step_N = 0.1;
  Rig rig(p);
  const Vec3 F(0.0, -0.6, 0.8);  // 1 N step
  const Vec3 tau = torque_for_force(pose_dh(), F);
  for (int k = 0; k < 12; ++k) {
    const Vec3 F_out = force_for_torque(pose_dh(), rig.tick(tau));
    const double expect = std::min(1.0, 0.1 * (k + 1));
    EXPECT_NEAR(F_out.norm(), expect, 1e-6) << "tick " << k;
    EXPECT_LT(parallel_error(F_out, F), 1e-9);
    // the tenth tick reaches the target exactly and is not limited
    EXPECT_EQ((rig.layer.status() & kSafetyForceImpulseLimited) != 0, k < 9)
        << "tick " << k;
  }
  // a step down is limited too (it is not a cut)
  const Vec3 F_out = force_for_torque(pose_dh(), rig.tick(Vec3::Zero()));
  EXPECT_NEAR(F_out.norm(), 0.9, 1e-6);
  EXPECT_TRUE(rig.layer.status() & kSafetyForceImpulseLimited);
}

TEST(SafetyLayer, CutsBypassTheImpulseLimit) {
  SafetyParams p = quiet();
  p.max_force_step_N = 0.01;
  Rig rig(p);
  for (int k = 0; k < 200; ++k) rig.tick(kSmall);
  ASSERT_EQ(rig.dev.written, kSmall);
  rig.layer.set_inputs(true, false);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
}

// wrist-centre position for a device reading, m, DH base frame
Vec3 tip(const Joints& q_device) {
  return omni_fk(OmniParams(), device_to_dh_joints(q_device)).p_base_m;
}

TEST(SafetyLayer, TipVelocityCutsWithHysteresis) {
  SafetyParams p = quiet();
  p.max_tip_speed_m_s = 1.5;
  p.resume_tip_speed_m_s = 1.0;
  Rig rig(p);
  // move t2 at a rate w: the tip speed is |p(k) - p(k-1)| / dt
  auto step = [&](double w_rad_s) {
    const Joints before = rig.dev.q;
    rig.dev.q[1] += w_rad_s * kDt;
    const Vec3 out = rig.tick(kSmall);
    EXPECT_NEAR(rig.layer.tip_speed_m_s(),
                (tip(rig.dev.q) - tip(before)).norm() / kDt, 1e-9);
    return out;
  };
  rig.tick(kSmall);
  // |dp/dt2| is about 0.133 m/rad here: 5 rad/s ~ 0.67 m/s
  EXPECT_EQ(step(5.0), kSmall);
  EXPECT_LT(rig.layer.tip_speed_m_s(), 1.0);
  EXPECT_EQ(step(14.0), Vec3::Zero());  // ~1.9 m/s
  EXPECT_GT(rig.layer.tip_speed_m_s(), 1.5);
  EXPECT_TRUE(rig.layer.status() & kSafetyVelocityExceeded);
  EXPECT_EQ(step(9.0), Vec3::Zero());  // ~1.2 m/s: inside the hysteresis band
  ASSERT_GT(rig.layer.tip_speed_m_s(), 1.0);
  ASSERT_LT(rig.layer.tip_speed_m_s(), 1.5);
  EXPECT_TRUE(rig.layer.status() & kSafetyVelocityExceeded);
  EXPECT_EQ(step(2.0), kSmall);  // under the resume speed
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
}

TEST(SafetyLayer, JointVelocityCutsAndUsesTheStampedPeriod) {
  SafetyParams p = quiet();
  p.max_joint_speed_rad_s = 12.0;
  p.resume_joint_speed_rad_s = 8.0;
  Rig rig(p);
  double t = 0.0;
  rig.layer.set_read_time(t);
  rig.tick(kSmall);
  // 0.015 rad in 1 ms is 15 rad/s: cut
  t += 1e-3;
  rig.dev.q[0] += 0.015;
  rig.layer.set_read_time(t);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
  EXPECT_NEAR(rig.layer.joint_speed_rad_s(), 15.0, 1e-9);
  EXPECT_TRUE(rig.layer.status() & kSafetyVelocityExceeded);
  // the same step over a stamped 2.5 ms is 6 rad/s: resumes
  t += 2.5e-3;
  rig.dev.q[0] += 0.015;
  rig.layer.set_read_time(t);
  EXPECT_EQ(rig.tick(kSmall), kSmall);
  EXPECT_NEAR(rig.layer.joint_speed_rad_s(), 6.0, 1e-9);
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
}

// the continuous torque of motor i, as docs/safety.md derives it: the largest
// torque a 0.88 N force in any direction needs at DH q = 0
Vec3 continuous_torques(double force_N) {
  const Mat3 D = Mat3{{-1, 0, 0}, {0, 1, -1}, {0, 0, 1}};  // dh -> motor
  const Mat3 DJt = D * fd_jacobian(Joints::Zero()).transpose();
  return force_N * DJt.rowwise().norm();
}

TEST(SafetyThermal, ContinuousTorqueIsTheContinuousForcesWorstCase) {
  Rig rig;
  const Vec3 expect = continuous_torques(0.88);
  EXPECT_LT((rig.layer.continuous_torque_Nm() - expect).norm(), 1e-8);
  // and they are under the motors' clamps, so the rating can be met
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(expect[i], SafetyParams().motor_torque_limit_Nm[i]);
  }
}

TEST(SafetyThermal, ContinuousForceIsSustainedForever) {
  SafetyParams p = quiet();
  p.thermal_time_constant_s = 0.2;  // 10 time constants in 2000 ticks
  p.thermal_warn = SafetyParams().thermal_warn;
  Rig rig(p);
  rig.dev.q = dh_to_device_joints(Joints::Zero());
  // 0.88 N along each device axis, one after another, 10 time constants each
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 tau = torque_for_force(Joints::Zero(), 0.88 * Vec3::Unit(axis));
    for (int k = 0; k < 2000; ++k) {
      ASSERT_LT((rig.tick(tau) - tau).norm(), 1e-15) << axis << " " << k;
      ASSERT_EQ(rig.layer.status(), kSafetyOk) << axis << " " << k;
    }
    EXPECT_LE(rig.layer.thermal_state().maxCoeff(), 1.0 + 1e-9);
  }
}

TEST(SafetyThermal, TimesToWarnCutAndResumeFollowTheExponential) {
  SafetyParams p = quiet();
  const double T = 1.0;
  p.thermal_time_constant_s = T;
  p.derate_at_cut = 1.0;  // no derating: the heating stays exponential
  Rig rig(p);
  const Vec3 tc = rig.layer.continuous_torque_Nm();
  const double r = 1.6;  // 1.6 x the continuous torque on motor 1
  const Vec3 tau(r * tc[0], 0.0, 0.0);
  ASSERT_LT(tau[0], p.motor_torque_limit_Nm[0]);
  const double u = r * r;
  // h after n writes is u (1 - exp(-n dt / T)); write n sees h_n
  const int n_warn =
      static_cast<int>(std::ceil(-T / kDt * std::log(1.0 - p.thermal_warn / u)));
  const int n_cut =
      static_cast<int>(std::ceil(-T / kDt * std::log(1.0 - p.thermal_cut / u)));
  for (int n = 0; n < n_cut; ++n) {
    ASSERT_EQ(rig.tick(tau), tau) << "write " << n;
    ASSERT_EQ((rig.layer.status() & kSafetyMotorWarm) != 0, n >= n_warn)
        << "write " << n;
  }
  EXPECT_EQ(rig.tick(tau), Vec3::Zero());
  EXPECT_TRUE(rig.layer.status() & kSafetyMotorHot);
  // cooling from h_cut (the state the cut write saw) to the resume level
  const double h_cut = u * (1.0 - std::exp(-n_cut * kDt / T));
  const int m_resume = static_cast<int>(
      std::ceil(T / kDt * std::log(h_cut / p.thermal_resume)));
  for (int m = 1; m < m_resume; ++m) {
    ASSERT_EQ(rig.tick(tau), Vec3::Zero()) << "cooling write " << m;
    ASSERT_TRUE(rig.layer.status() & kSafetyMotorHot);
  }
  EXPECT_EQ(rig.tick(tau), tau);
  EXPECT_FALSE(rig.layer.status() & kSafetyMotorHot);
  EXPECT_NEAR(n_cut * kDt, -T * std::log(1.0 - 2.0 / 2.56), kDt);
}

TEST(SafetyThermal, DeratesLinearlyAndSettlesWhereHeatingMeetsCooling) {
  // a moderate overload does not reach the cut: the derated torque settles
  // where u d(x)^2 = warn + (cut - warn) x, d(x) = 1 - (1 - d_cut) x
  SafetyParams p = quiet();
  p.thermal_time_constant_s = 0.5;
  p.derate_at_cut = 0.5;
  Rig rig(p);
  const double r = 1.6;
  const Vec3 tau(r * rig.layer.continuous_torque_Nm()[0], 0.0, 0.0);
  for (int n = 0; n < 10000; ++n) {  // 20 time constants
    rig.read_only();
    const double h = rig.layer.thermal_state().maxCoeff();  // what write n sees
    const Vec3 out = rig.write_only(tau);
    const double x = std::max(0.0, (h - 1.2) / (2.0 - 1.2));
    ASSERT_NEAR(out[0] / tau[0], 1.0 - 0.5 * x, 1e-12) << "write " << n;
    ASSERT_EQ((rig.layer.status() & kSafetyMotorWarm) != 0, h > 1.2);
    ASSERT_FALSE(rig.layer.status() & kSafetyMotorHot);
  }
  // 0.25 u x^2 - (u + 0.8) x + (u - 1.2) = 0, the smaller root
  const double u = r * r, a = 0.25 * u, b = -(u + 0.8), c = u - 1.2;
  const double x_star = (-b - std::sqrt(b * b - 4 * a * c)) / (2 * a);
  EXPECT_NEAR(rig.dev.written[0] / tau[0], 1.0 - 0.5 * x_star, 1e-6);
  EXPECT_NEAR(rig.layer.thermal_state()[0], 1.2 + 0.8 * x_star, 1e-6);
  // cools back under warn with the command removed, and is not derated any more
  for (int n = 0; n < 2000; ++n) rig.tick(Vec3::Zero());
  EXPECT_EQ(rig.tick(tau), tau);
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
}

TEST(SafetyThermal, HeatsOverAStampedGapWithTheTorqueHeldThrough) {
  // each read adds the interval since the last one, at the torque the
  // device held over it: a 0.5 s gap heats by u (1 - e^(-0.5/T))
  SafetyParams p = quiet();
  p.thermal_time_constant_s = 1.0;
  Rig rig(p);
  const double r = 1.6, u = r * r;
  const Vec3 tau(r * rig.layer.continuous_torque_Nm()[0], 0.0, 0.0);
  rig.layer.set_read_time(10.0);
  EXPECT_EQ(rig.tick(tau), tau);
  EXPECT_EQ(rig.layer.thermal_state()[0], 0.0);  // nothing held before
  rig.layer.set_read_time(10.5);
  rig.read_only();
  const double h1 = u * (1.0 - std::exp(-0.5));
  EXPECT_NEAR(rig.layer.thermal_state()[0], h1, 1e-12);
  EXPECT_EQ(rig.write_only(Vec3::Zero()), Vec3::Zero());
  rig.layer.set_read_time(11.5);
  rig.read_only();
  EXPECT_NEAR(rig.layer.thermal_state()[0], h1 * std::exp(-1.0), 1e-12);
  EXPECT_EQ(rig.layer.thermal_state()[1], 0.0);
}

TEST(SafetyThermal, ALargeOverloadIsCutDespiteDerating) {
  // u d_cut^2 > cut: the derated torque still heats past the cut
  SafetyParams p = quiet();
  p.thermal_time_constant_s = 0.5;
  p.motor_torque_limit_Nm = {1.0, 1.0, 1.0};
  Rig rig(p);
  const Vec3 tau(3.5 * rig.layer.continuous_torque_Nm()[0], 0.0, 0.0);
  ASSERT_GT(3.5 * 3.5 * 0.25, p.thermal_cut);
  int n = 0;
  double x_max = 0.0;
  for (; n < 20000; ++n) {
    rig.read_only();
    const double h = rig.layer.thermal_state().maxCoeff();  // what write n sees
    const Vec3 out = rig.write_only(tau);
    if (out == Vec3::Zero()) {
      EXPECT_GE(h, p.thermal_cut);
      break;
    }
    // linear all the way from warn to cut
    const double x = std::max(0.0, (h - 1.2) / (2.0 - 1.2));
    ASSERT_NEAR(out[0] / tau[0], 1.0 - 0.5 * x, 1e-12) << "write " << n;
    x_max = std::max(x_max, x);
  }
  EXPECT_LT(n, 20000);
  EXPECT_GT(x_max, 0.99);
  EXPECT_TRUE(rig.layer.status() & kSafetyMotorHot);
}

TEST(SafetyThermal, PeakForceIsCutWithinItsClosedFormTime) {
  // 3.3 N at the nominal pose, in the direction worst for motor 1; the
  // torque clamp bounds what it can ask for (docs/safety.md)
  SafetyParams p = quiet();
  p.thermal_time_constant_s = SafetyParams().thermal_time_constant_s;
  p.derate_at_cut = 1.0;
  Rig rig(p);
  rig.dev.q = dh_to_device_joints(Joints::Zero());
  rig.tick(Vec3::Zero());
  const Vec3 tc = rig.layer.continuous_torque_Nm();
  const double T = p.thermal_time_constant_s;
  const Vec3 tau_peak = tc * (3.3 / 0.88);
  Vec3 tau_sent = tau_peak * std::min({1.0, 0.2 / tau_peak[0],
                                       0.35 / tau_peak[1], 0.2 / tau_peak[2]});
  double u = 0.0;
  for (int i = 0; i < 3; ++i) u = std::max(u, std::pow(tau_sent[i] / tc[i], 2));
  ASSERT_GT(u, p.thermal_cut);
  const int n_cut =
      static_cast<int>(std::ceil(-T / kDt * std::log(1.0 - p.thermal_cut / u)));
  // each motor's worst-direction peak torque, all at once (the worst case)
  int n = 0;
  while (n < 200000 && rig.tick(tau_peak) != Vec3::Zero()) ++n;
  EXPECT_EQ(n, n_cut);
  EXPECT_TRUE(rig.layer.status() & kSafetyMotorHot);
}

TEST(SafetyComm, LostAfterNFailedReadsAndLatchedForMGoodOnes) {
  SafetyParams p = quiet();
  p.comm_lost_reads = 3;
  p.comm_resume_reads = 5;
  Rig rig(p);
  rig.tick(kSmall);
  // a failed read: zero even if the caller writes anyway, not yet comm_lost
  rig.dev.read_error = DeviceError::kIo;
  for (int k = 1; k <= 3; ++k) {
    EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
    EXPECT_EQ(rig.read, DeviceError::kIo);
    EXPECT_TRUE(rig.layer.status() & kSafetyNoReading);
    EXPECT_EQ((rig.layer.status() & kSafetyCommLost) != 0, k >= 3) << k;
  }
  rig.dev.read_error = DeviceError::kOk;
  for (int k = 1; k < 5; ++k) {
    EXPECT_EQ(rig.tick(kSmall), Vec3::Zero()) << k;
    EXPECT_EQ(rig.read, DeviceError::kOk);
    EXPECT_EQ(rig.layer.status(), kSafetyCommLost);
  }
  // one more failure restarts the count of good reads
  rig.dev.read_error = DeviceError::kTimeout;
  rig.tick(kSmall);
  rig.dev.read_error = DeviceError::kOk;
  for (int k = 1; k < 5; ++k) EXPECT_EQ(rig.tick(kSmall), Vec3::Zero()) << k;
  EXPECT_EQ(rig.tick(kSmall), kSmall);
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
}

TEST(SafetyComm, TwoFailuresAreNotALoss) {
  SafetyParams p = quiet();
  p.comm_lost_reads = 3;
  Rig rig(p);
  rig.dev.read_error = DeviceError::kIo;
  rig.tick(kSmall);
  rig.tick(kSmall);
  rig.dev.read_error = DeviceError::kOk;
  EXPECT_EQ(rig.tick(kSmall), kSmall);
}

TEST(SafetyComm, NonFiniteReadingIsAFailedRead) {
  Rig rig;
  rig.dev.q[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
  EXPECT_EQ(rig.read, DeviceError::kSensorFault);
}

TEST(SafetyInputs, DockedAndDeadman) {
  SafetyParams p = quiet();
  p.require_deadman = true;
  Rig rig(p);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());  // not pressed
  EXPECT_EQ(rig.layer.status(), kSafetyDeadmanReleased);
  rig.layer.set_inputs(false, true);
  EXPECT_EQ(rig.tick(kSmall), kSmall);
  rig.layer.set_inputs(true, true);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
  EXPECT_EQ(rig.layer.status(), kSafetyDocked);
  rig.layer.set_inputs(false, true);
  EXPECT_EQ(rig.tick(kSmall), kSmall);
  // without require_deadman the button does not matter
  Rig free_rig;
  free_rig.layer.set_inputs(false, false);
  EXPECT_EQ(free_rig.tick(kSmall), kSmall);
}

TEST(SafetyCommand, NonFiniteTorqueSendsZero) {
  Rig rig;
  rig.tick(kSmall);
  const Vec3 out = rig.tick(Vec3(0.0, std::nan(""), 0.0));
  EXPECT_EQ(out, Vec3::Zero());
  EXPECT_EQ(rig.write, DeviceError::kInvalidCommand);
  EXPECT_EQ(rig.layer.status(), kSafetyInvalidCommand);
  EXPECT_EQ(rig.tick(kSmall), kSmall);
}

TEST(ServoWatchdog, ExpiresAfterNPeriodsWithoutAKick) {
  ServoWatchdog w(1e-3, 10);
  EXPECT_FALSE(w.armed());
  EXPECT_FALSE(w.expired(100.0));  // not armed before the first kick
  w.kick(5.0);
  EXPECT_TRUE(w.armed());
  EXPECT_FALSE(w.expired(5.0095));
  EXPECT_TRUE(w.expired(5.0105));
  w.kick(5.0105);
  EXPECT_FALSE(w.expired(5.02));
  EXPECT_TRUE(w.expired(std::nan("")));
  w.disarm();
  EXPECT_FALSE(w.expired(1e9));
  EXPECT_NEAR(w.timeout_s(), 0.01, 1e-15);
  EXPECT_THROW(ServoWatchdog(0.0, 10), std::invalid_argument);
  EXPECT_THROW(ServoWatchdog(1e-3, 0), std::invalid_argument);
}

TEST(SafetyLayer, WatchdogZeroesTheDeviceAndTheServoRampsBack) {
  SafetyParams p = quiet();
  p.watchdog_periods = 5;
  p.ramp_s = 0.01;
  Rig rig(p);
  double t = 0.0;
  for (int k = 0; k < 20; ++k, t += kDt) {
    rig.layer.set_read_time(t);
    rig.tick(kSmall);
    EXPECT_FALSE(rig.layer.service_watchdog(t + 0.5 * kDt));
  }
  ASSERT_EQ(rig.dev.written, kSmall);
  const double last = t - kDt;
  EXPECT_FALSE(rig.layer.service_watchdog(last + 4.9e-3));
  EXPECT_EQ(rig.dev.written, kSmall);
  const int writes = rig.dev.writes;
  EXPECT_TRUE(rig.layer.service_watchdog(last + 5.1e-3));
  EXPECT_EQ(rig.dev.writes, writes + 1);
  EXPECT_EQ(rig.dev.written, Vec3::Zero());
  EXPECT_TRUE(rig.layer.status() & kSafetyWatchdogExpired);
  // the servo comes back: the ramp starts from zero
  t = last + 6e-3;
  rig.layer.set_read_time(t);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
  EXPECT_FALSE(rig.layer.status() & kSafetyWatchdogExpired);
  rig.layer.set_read_time(t + kDt);
  EXPECT_LT((rig.tick(kSmall) - 0.1 * kSmall).norm(), 1e-15);
  EXPECT_FALSE(rig.layer.service_watchdog(t + kDt + 1e-3));
}

TEST(SafetyLayer, LimitsStillHoldWhenThePoseChangesUnderTheRateLimiter) {
  // the torque held by the rate limiter makes more force at a pose nearer
  // the shoulder axis; the final clamp keeps the force limit there too
  SafetyParams p = quiet();
  p.max_force_N = 1.0;
  p.max_force_step_N = 0.05;
  p.motor_torque_limit_Nm = {10.0, 10.0, 10.0};
  Rig rig(p);
  const Vec3 F(1.0, 0.0, 0.0);  // along device x: the waist motor's work
  const Vec3 tau = torque_for_force(pose_dh(), 3.0 * F);
  for (int k = 0; k < 40; ++k) rig.tick(tau);
  ASSERT_NEAR(force_for_torque(pose_dh(), rig.dev.written).norm(), 1.0, 1e-6);
  // reach toward the joint-1 axis: the same waist torque is a larger force
  Joints near_axis = pose_dh();
  near_axis[1] = 1.2;
  near_axis[2] = 0.2;
  rig.dev.q = dh_to_device_joints(near_axis);
  ASSERT_GT(force_for_torque(near_axis, rig.dev.written).norm(), 1.05);
  const Vec3 out = rig.tick(tau);
  EXPECT_LE(force_for_torque(near_axis, out).norm(), 1.0 + 1e-6);
  EXPECT_TRUE(rig.layer.status() & kSafetyForceClamped);
}

// the chain of docs/safety.md, with the project's controller behind it
TEST(SafetyLayer, ServoTickThroughTheLayer) {
  ControllerParams cp;
  cp.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  Controller controller(cp), reference(cp);
  ScriptedDevice dev;
  SafetyParams p = quiet();
  p.ramp_s = 0.01;
  SafetyLayer layer(&dev, p);
  const Joints t = (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();
  dev.q = t;
  ControlOutput out, ref;
  for (int k = 0; k <= 12; ++k) {
    const ServoTickResult r = servo_tick(&layer, &controller, &out);
    ASSERT_EQ(r.read, DeviceError::kOk);
    reference.tick(device_to_dh_joints(t), &ref);
    ASSERT_GT(ref.tau_motor_Nm.norm(), 1e-3);
    ASSERT_LT(ref.force_device_N.norm(), p.max_force_N);
    const double s = std::min(1.0, k / 10.0);
    EXPECT_LT((dev.written - s * ref.tau_motor_Nm).norm(), 1e-12) << k;
  }
  // the layer's torque-to-force map agrees with the controller's own
  EXPECT_LT((layer.force_device_N(out.tau_motor_Nm) - out.force_device_N).norm(),
            1e-6 * (1.0 + out.force_device_N.norm()));
  // a failed read reaches the device as zero through both
  dev.read_error = DeviceError::kTimeout;
  EXPECT_TRUE(servo_tick(&layer, &controller, &out).zeroed);
  EXPECT_EQ(dev.written, Vec3::Zero());
}

TEST(SafetyLayer, ServoPathAllocatesNothing) {
  SafetyParams p;  // defaults: every limit live
  p.comm_lost_reads = 1;
  p.comm_resume_reads = 2;
  Rig rig(p);
  const Vec3 big(1.0, -1.0, 0.5);
  double t = 0.0;
  testing::AllocationScope scope;
  for (int k = 0; k < 2000; ++k, t += kDt) {
    rig.dev.read_error = (k % 97 == 0) ? DeviceError::kIo : DeviceError::kOk;
    rig.dev.q[0] += (k % 301 == 0) ? 0.05 : 1e-4;
    rig.layer.set_inputs(k % 503 == 0, true);
    rig.layer.set_read_time(t);
    rig.tick(k % 200 == 0 ? Vec3(std::nan(""), 0, 0) : big);
    rig.layer.service_watchdog(t);
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace vmh
