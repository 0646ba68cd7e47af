// controller/omni_ratings: the motor torque limits derived from the rated
// force, checked by routes that do not use its code path: the closed form of
// the nominal pose, and the motor torques of forces along the device axes
// through a finite-difference Jacobian of omni_fk in the motor (device)
// joint angles, so that neither J_v nor the DH-to-motor torque map of
// device_frame.h is reused.
#include "controller/omni_ratings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh {
namespace {

// d p_base / d t for the actuated device joints t1..t3 (t3 the absolute
// forearm angle), central differences of omni_fk, m/rad
Mat3 jacobian_in_motor_angles(const OmniParams& omni, const Joints& t_device) {
  constexpr double h = 1e-6;
  Mat3 J;
  for (int j = 0; j < 3; ++j) {
    Joints a = t_device, b = t_device;
    a[j] += h;
    b[j] -= h;
    J.col(j) = (omni_fk(omni, device_to_dh_joints(a)).p_base_m -
                omni_fk(omni, device_to_dh_joints(b)).p_base_m) /
               (2.0 * h);
  }
  return J;
}

// the motor torques that hold a force F (device frame, N) at the wrist
// centre, by virtual work in the motor angles: tau = J_t^T F_base
Vec3 motor_torques_for(const OmniParams& omni, const Joints& t_device,
                       const Vec3& F_device_N) {
  return jacobian_in_motor_angles(omni, t_device).transpose() *
         device_to_base_vector(F_device_N);
}

TEST(OmniRatings, RatedLimitsAreTheClosedFormAtTheNominalPose) {
  // DH q = 0: upper arm level (l1 from the shoulder), forearm vertical (l2):
  // the waist and the shoulder see the force at lever l1, the elbow at l2
  const OmniParams omni;
  const auto lim = motor_torque_limits_Nm(omni, TorqueLimits::kRated);
  EXPECT_NEAR(lim[0], 3.3 * omni.l1_m, 1e-12);
  EXPECT_NEAR(lim[1], 3.3 * omni.l1_m, 1e-12);
  EXPECT_NEAR(lim[2], 3.3 * omni.l2_m, 1e-12);
}

TEST(OmniRatings, OmniParamsDefaultsAreTheSampleClamps) {
  // the default until the rated limits are (docs/safety.md says why not yet)
  const OmniParams omni;
  EXPECT_EQ(omni.motor_torque_limit_Nm,
            motor_torque_limits_Nm(omni, TorqueLimits::kOpenHapticsSamples));
  const auto rated = motor_torque_limits_Nm(omni, TorqueLimits::kRated);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(rated[static_cast<std::size_t>(i)],
              omni.motor_torque_limit_Nm[static_cast<std::size_t>(i)]);
  }
}

// The acceptance: at the home pose a 3.3 N force along each device
// axis, either sign, is within the rated limits; and the limits are tight
// (each motor reaches its limit along one axis), while the sample clamps
// let no more than 1.5 N through along x and z.
TEST(OmniRatings, RatedForceAlongEachDeviceAxisFitsAtHome) {
  const OmniParams omni;
  const Joints home = Joints::Zero();  // device angles 0 = DH 0
  ASSERT_TRUE(device_to_dh_joints(home).isZero(0.0));
  const auto rated = motor_torque_limits_Nm(omni, TorqueLimits::kRated);
  const auto samples = motor_torque_limits_Nm(omni, TorqueLimits::kOpenHapticsSamples);
  std::array<double, 3> largest{};
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      const Vec3 F = sign * 3.3 * Vec3::Unit(axis);
      const Vec3 tau = motor_torques_for(omni, home, F);
      bool samples_hold = true;
      for (int i = 0; i < 3; ++i) {
        const auto k = static_cast<std::size_t>(i);
        EXPECT_LE(std::abs(tau[i]), rated[k] + 1e-9)
            << "axis " << axis << " sign " << sign << " motor " << i + 1;
        largest[k] = std::max(largest[k], std::abs(tau[i]));
        samples_hold = samples_hold && std::abs(tau[i]) <= samples[k];
      }
      // 3.3 N along any axis is over some sample clamp (1.5 N along x and
      // z, 2.62 N along y): the limitation the rated limits remove
      EXPECT_FALSE(samples_hold) << "axis " << axis;
    }
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(largest[static_cast<std::size_t>(i)], rated[static_cast<std::size_t>(i)], 1e-7)
        << "motor " << i + 1 << ": the limit is not reached along any axis";
  }
  // the sample clamp of motor 1 at lever l1 along device x
  EXPECT_NEAR(samples[0] / omni.l1_m, 1.4998, 1e-4);
}

// At other poses motor_torque_per_force_m is the worst direction's torque:
// against a brute-force search over directions with the finite-difference
// Jacobian in motor angles.
TEST(OmniRatings, PerForceTorqueIsTheWorstDirection) {
  const OmniParams omni;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    Joints t = Joints::Zero();
    for (int j = 0; j < 3; ++j) t[j] = u(rng);
    const Vec3 r = motor_torque_per_force_m(omni, device_to_dh_joints(t));
    const Mat3 Jt = jacobian_in_motor_angles(omni, t).transpose();
    Vec3 worst = Vec3::Zero();
    for (int k = 0; k < 20000; ++k) {
      const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
      worst = worst.cwiseMax((Jt * dir).cwiseAbs());
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(worst[i], r[i] + 1e-7) << "trial " << trial << " motor " << i + 1;
      EXPECT_GT(worst[i], 0.995 * r[i]) << "trial " << trial << " motor " << i + 1;
    }
  }
}

TEST(OmniRatings, ContinuousForceScalesTheSameWay) {
  const OmniParams omni;
  const auto c = motor_torques_for_force_Nm(omni, omni.continuous_force_N);
  EXPECT_NEAR(c[0], 0.88 * 0.13335, 1e-12);
  EXPECT_NEAR(c[2], 0.88 * 0.13335, 1e-12);
}

TEST(OmniRatings, NamesRoundTripAndBadTextIsNamed) {
  for (TorqueLimits t : {TorqueLimits::kRated, TorqueLimits::kOpenHapticsSamples}) {
    EXPECT_EQ(parse_torque_limits(torque_limits_name(t)), t);
  }
  try {
    parse_torque_limits("vendor");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'vendor'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("openhaptics_samples"), std::string::npos);
  }
}

}  // namespace
}  // namespace vmh
