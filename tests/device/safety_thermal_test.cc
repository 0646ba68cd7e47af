// device/safety.h's thermal model and communication-loss latch against a
// scripted device: the I^2 t state's times to warn, cut and resume follow its
// exponential solution, the continuous force is sustained forever, and N
// failed reads in a row cut until M good ones.
#include "device/safety.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "tests/device/safety_rig.h"

namespace vmh {
namespace {

using namespace testing;  // NOLINT: the shared rig (safety_rig.h)

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

}  // namespace
}  // namespace vmh
