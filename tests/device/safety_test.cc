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
#include "tests/device/safety_rig.h"
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

using namespace testing;  // NOLINT: the shared rig (safety_rig.h)

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
  const double lim = SafetyParams().motor_torque_limit_Nm[0];
  const Vec3 tau(2.5 * lim, 0.1, -0.05);  // motor 1 at 2.5x its limit
  const Vec3 out = rig.tick(tau);
  EXPECT_NEAR(out[0], lim, 1e-12);
  EXPECT_LT((out - tau / 2.5).norm(), 1e-12);
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

// Readings stamped much closer than a servo period (a source catching up
// after a stall) are measured over half a period at least, so one encoder
// count does not read as a fling; a real fling still does.
TEST(SafetyLayer, ReadingsCloserThanHalfAPeriodAreNotAFling) {
  SafetyParams p = quiet();
  p.max_joint_speed_rad_s = 2.0;
  p.resume_joint_speed_rad_s = 1.0;
  Rig rig(p);
  const double count_rad = 2.0 * 3.14159265358979323846 / 15000.0;
  double t = 0.0;
  rig.layer.set_read_time(t);
  rig.tick(kSmall);
  // one count 0.1 ms later: 4.2 rad/s over 0.1 ms, 0.84 rad/s over 0.5 ms
  t += 1e-4;
  rig.dev.q[0] += count_rad;
  rig.layer.set_read_time(t);
  EXPECT_EQ(rig.tick(kSmall), kSmall);
  EXPECT_NEAR(rig.layer.joint_speed_rad_s(), count_rad / (0.5 * kDt), 1e-9);
  EXPECT_EQ(rig.layer.status(), kSafetyOk);
  // 0.01 rad in 0.1 ms still cuts (20 rad/s over the half period)
  t += 1e-4;
  rig.dev.q[0] += 0.01;
  rig.layer.set_read_time(t);
  EXPECT_EQ(rig.tick(kSmall), Vec3::Zero());
  EXPECT_TRUE(rig.layer.status() & kSafetyVelocityExceeded);
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
