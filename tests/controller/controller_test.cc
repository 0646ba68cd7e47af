// The Controller end to end, from joint angles to device force and torques.
//
// The thesis's claims (docs/sources.md §2, thesis ch. 4) are checked as numbers
// on static configurations. Each configuration is built from a wanted wrist
// centre and stylus axis in the device frame through the inverse kinematics,
// and the expected forces are written out by hand from the geometry of the
// circle and sphere, not taken from the controller's own functions.
#include "controller/controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "tests/support/random_joints.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;
constexpr double kL = 50.0;  // mm, listing D.1
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Joint angles (DH) that put the wrist centre at p_mm and the stylus axis
// along `axis`, both in the device frame.
Joints pose_q(const Vec3& p_mm, const Vec3& axis) {
  const OmniParams omni;
  const Vec3 z = axis.normalized();
  const Vec3 x = (std::abs(z.y()) < 0.9 ? Vec3::UnitY() : Vec3::UnitX())
                     .cross(z)
                     .normalized();
  Mat3 R_device;
  R_device << x, z.cross(x), z;
  const IkSolutions sol =
      omni_ik_pose(omni, device_mm_to_base(omni, p_mm),
                   device_to_base_rotation(R_device), Joints::Zero());
  EXPECT_EQ(sol.status, IkStatus::kOk) << "unreachable " << p_mm.transpose();
  const int k = omni_ik_nearest(sol, Joints::Zero());
  return k >= 0 ? sol.q_dh[static_cast<std::size_t>(k)] : Joints::Zero();
}

// the thesis's cases: kind, K_pos (N/mm), K_ornt as a multiple of 2 pi L
ControllerParams thesis_case(int n) {
  ControllerParams p;
  const double kpos[] = {0, 0.5, 0.5, 0.6, 0.5, 0.5, 0.5};
  const double kornt[] = {0, 0, 0.5, 0.5, 1.0, 0, 0.5};
  p.vm.kind = n <= 4 ? VmKind::kCircle : VmKind::kSphere;
  p.vm.length_mm = kL;
  p.gains.k_pos_N_per_mm = kpos[n];
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(kornt[n], kL);
  // the claims are about direction; keep the device limits out of the way
  p.force_limit_N = 1e9;
  p.omni.motor_torque_limit_Nm = {1e9, 1e9, 1e9};
  return p;
}

ControlOutput tick_once(const ControllerParams& p, const Joints& q) {
  Controller c(p);
  ControlOutput out;
  c.tick(q, &out);
  return out;
}

// point on the circle of radius kL in the device x-y plane at angle a, and
// the radial / tangential (increasing angle) unit vectors there
Vec3 on_circle(double a, double r = kL, double z = 0.0) {
  return Vec3(r * std::cos(a), r * std::sin(a), z);
}
Vec3 radial(double a) { return Vec3(std::cos(a), std::sin(a), 0.0); }
Vec3 tangent(double a) { return Vec3(-std::sin(a), std::cos(a), 0.0); }

double angle_between(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// --------------------------------------------------------------- basics

TEST(Controller, RmPoseIsTheWristCentreAndStylusAxis) {
  const Vec3 p(20.0, -10.0, 30.0);
  const Vec3 a = Vec3(0.3, 0.2, 0.9).normalized();
  const ControlOutput out = tick_once(thesis_case(1), pose_q(p, a));
  EXPECT_LT((out.p_rm_mm - p).norm(), 1e-9);
  EXPECT_LT((out.axis_rm - a).norm(), 1e-9);
}

TEST(Controller, InvalidParametersNameTheField) {
  ControllerParams p;
  p.vm.length_mm = -5;
  try {
    Controller c(p);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("vm.length_mm"), std::string::npos)
        << e.what();
  }
  ControllerParams q;
  q.placement_options.weights.setZero();
  EXPECT_THROW(Controller c(q), std::invalid_argument);
  ControllerParams r;
  r.gains.k_pos_N_per_mm = kNaN;
  EXPECT_THROW(Controller c(r), std::invalid_argument);
  ControllerParams s;
  s.vm.R_pivot(0, 0) = 2.0;
  EXPECT_THROW(Controller c(s), std::invalid_argument);
}

TEST(Controller, StatusNamesAreDistinct) {
  EXPECT_STREQ(status_flag_name(kStatusOk), "ok");
  for (int i = 0; i < kStatusFlagCount; ++i) {
    for (int j = i + 1; j < kStatusFlagCount; ++j) {
      EXPECT_STRNE(status_flag_name(1u << i), status_flag_name(1u << j));
    }
    EXPECT_STRNE(status_flag_name(1u << i), "unknown");
  }
  EXPECT_TRUE(is_fault(kStatusInvalidInput | kStatusForceSaturated));
  EXPECT_FALSE(is_fault(kStatusVmSingular | kStatusForceSaturated));
}

TEST(Controller, ThesisOrientationGainIsAMultipleOfTheCircumference) {
  EXPECT_NEAR(thesis_orientation_gain(0.5, 50.0), 0.5 * 2 * kPi * 50.0, 1e-12);
  EXPECT_NEAR(thesis_orientation_gain(1.0, 50.0), 314.159265358979, 1e-9);
}

// ------------------------------------------- cases 1 and 5: position only

TEST(ThesisClaims, Case1OnThePathThereIsNoForce) {
  const ControllerParams p = thesis_case(1);
  for (double a : {-2.5, -1.0, 0.3, 1.4, 2.9}) {
    // any stylus orientation
    const ControlOutput out =
        tick_once(p, pose_q(on_circle(a), Vec3(0.2, -0.4, 1.0)));
    EXPECT_LT(out.force_device_N.norm(), 1e-9) << "a = " << a;
  }
}

TEST(ThesisClaims, Case1OffThePathForceIsNormalAndProportionalToDistance) {
  const ControllerParams p = thesis_case(1);
  for (double a : {-2.5, -1.0, 0.3, 1.4, 2.9}) {
    for (double r : {30.0, 45.0, 58.0, 70.0}) {
      for (double z : {-15.0, 0.0, 10.0}) {
        const Vec3 rm = on_circle(a, r, z);
        const ControlOutput out =
            tick_once(p, pose_q(rm, Vec3(0.1, 0.5, 1.0)));
        // nearest point of the circle, by hand: radial projection onto it
        const Vec3 nearest = kL * radial(a);
        const double distance = std::hypot(r - kL, z);
        const Vec3 F = out.force_device_N;
        EXPECT_NEAR(F.norm(), 0.5 * distance, 1e-9 * distance);
        EXPECT_LT(angle_between(F, nearest - rm), 1e-9);
        // normal to the path: no component along the tangent
        EXPECT_NEAR(F.dot(tangent(a)), 0.0, 1e-9);
      }
    }
  }
}

TEST(ThesisClaims, Case1ForceDoesNotDependOnTheStylus) {
  const ControllerParams p = thesis_case(1);
  const Vec3 rm = on_circle(0.7, 62.0, 5.0);
  const Vec3 F0 =
      tick_once(p, pose_q(rm, Vec3(0.0, 0.0, 1.0))).force_device_N;
  for (const Vec3& a : {Vec3(1, 0, 0.2), Vec3(-0.5, 0.5, 1.0),
                        Vec3(0.3, -1.0, 0.4)}) {
    const Vec3 F = tick_once(p, pose_q(rm, a)).force_device_N;
    EXPECT_LT((F - F0).norm(), 1e-9);
  }
}

TEST(ThesisClaims, Case5OffTheSphereForceIsRadialAndProportional) {
  const ControllerParams p = thesis_case(5);
  for (const Vec3& dir : {Vec3(1, 0.2, -0.3), Vec3(-0.4, 1, 0.5),
                          Vec3(0.3, -0.6, 0.8), Vec3(0.5, 0.5, -0.7)}) {
    for (double r : {30.0, 50.0, 65.0}) {
      const Vec3 rm = r * dir.normalized();
      for (const Vec3& a : {Vec3(0, 0, 1), Vec3(0.6, 0.3, 0.7)}) {
        const ControlOutput out = tick_once(p, pose_q(rm, a));
        const Vec3 F = out.force_device_N;
        const Vec3 nearest = kL * dir.normalized();
        EXPECT_NEAR(F.norm(), 0.5 * std::abs(r - kL), 1e-9);
        if (std::abs(r - kL) > 0) {
          EXPECT_LT(angle_between(F, nearest - rm), 1e-9);
        }
      }
    }
  }
}

// ---------------------------------- cases 2 and 6: position + orientation

// On the circle with the stylus in the plane at angle b, the force is
// tangential, toward X(theta_R), with magnitude K_ornt |d| L / (L^2 + 1),
// d = theta_V - theta_R (worked out in docs/control.md: the projection keeps
// the part of (0, K_ornt d e_z) that J_V = (L t; e_z) cannot absorb).
TEST(ThesisClaims, Case2OnThePathForcePointsAlongItTowardXThetaR) {
  const ControllerParams p = thesis_case(2);
  const double K = thesis_orientation_gain(0.5, kL);
  for (double a : {-2.0, 0.4, 1.8}) {
    for (double d : {-0.6, -0.2, 0.15, 0.5}) {
      const double b = a - d;  // stylus angle: theta_R
      const ControlOutput out =
          tick_once(p, pose_q(on_circle(a), radial(b) + Vec3(0, 0, 0.3)));
      const Vec3 F = out.force_device_N;
      const Vec3 x_r = kL * radial(b);
      EXPECT_NEAR(F.norm(), K * std::abs(d) * kL / (kL * kL + 1), 1e-9);
      EXPECT_NEAR(F.dot(radial(a)), 0.0, 1e-9);  // along the path
      EXPECT_NEAR(F.z(), 0.0, 1e-9);
      EXPECT_GT(F.dot(x_r - on_circle(a)), 0.0);  // toward X(theta_R)
      EXPECT_LT((out.x_r_mm - x_r).norm(), 1e-9);
    }
  }
}

// Off the path the force points between X(theta_V) and X(theta_R), nearer
// X(theta_V) (thesis §4.1.2): checked 10-15 mm off the path within 0.6 rad
// of misalignment. Closer to the path the orientation term wins (next test).
TEST(ThesisClaims, Case2OffThePathForcePointsBetweenNearerXThetaV) {
  const ControllerParams p = thesis_case(2);
  int checked = 0;
  for (double a : {-1.2, 0.5, 2.2}) {
    for (double r : {35.0, 40.0, 60.0, 65.0}) {
      for (double d : {-0.6, -0.3, 0.3, 0.6}) {
        const Vec3 rm = on_circle(a, r);
        const Vec3 x_v = kL * radial(a);
        const Vec3 x_r = kL * radial(a - d);
        const Vec3 F =
            tick_once(p, pose_q(rm, radial(a - d) + Vec3(0, 0, 0.2)))
                .force_device_N;
        const double to_v = angle_between(F, x_v - rm);
        const double to_r = angle_between(F, x_r - rm);
        const double between = angle_between(x_v - rm, x_r - rm);
        EXPECT_NEAR(to_v + to_r, between, 1e-9) << "not between";
        EXPECT_LT(to_v, to_r) << "a " << a << " r " << r << " d " << d;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 48);
}

// Near the path the orientation term dominates, as the thesis says of
// Fig. 4.6 ("when there is small error based on X(theta_V) the force
// generated is strongly based on the error in orientation"): 5 mm outside
// with 0.6 rad of misalignment the force is nearer X(theta_R), still between.
TEST(ThesisClaims, Case2NearThePathForceLeansTowardXThetaR) {
  const Vec3 rm = on_circle(0.5, 55.0);
  const Vec3 x_v = kL * radial(0.5);
  const Vec3 x_r = kL * radial(0.5 - 0.6);
  const Vec3 F = tick_once(thesis_case(2),
                           pose_q(rm, radial(0.5 - 0.6) + Vec3(0, 0, 0.2)))
                     .force_device_N;
  EXPECT_GT(angle_between(F, x_v - rm), angle_between(F, x_r - rm));
  EXPECT_NEAR(angle_between(F, x_v - rm) + angle_between(F, x_r - rm),
              angle_between(x_v - rm, x_r - rm), 1e-9);
}

// Case 3 raises K_pos from 0.5 to 0.6 at the same K_ornt: the pull onto the
// path grows by exactly 1.2, the along-path part is unchanged, and the force
// turns toward X(theta_V).
TEST(ThesisClaims, Case3WeighsThePositionErrorMore) {
  const Vec3 rm = on_circle(0.5, 40.0);
  const Joints q = pose_q(rm, radial(0.2) + Vec3(0, 0, 0.2));
  const Vec3 F2 = tick_once(thesis_case(2), q).force_device_N;
  const Vec3 F3 = tick_once(thesis_case(3), q).force_device_N;
  EXPECT_NEAR(F3.dot(radial(0.5)), 1.2 * F2.dot(radial(0.5)), 1e-9);
  EXPECT_NEAR(F3.dot(tangent(0.5)), F2.dot(tangent(0.5)), 1e-9);
  const Vec3 x_v = kL * radial(0.5);
  EXPECT_LT(angle_between(F3, x_v - rm), angle_between(F2, x_v - rm));
}

// Case 4 doubles K_ornt: on the path the force doubles exactly; off it the
// along-path part doubles and the force turns toward X(theta_R).
TEST(ThesisClaims, Case4WeighsTheOrientationErrorMore) {
  const Joints on = pose_q(on_circle(0.5), radial(0.2) + Vec3(0, 0, 0.2));
  const Vec3 F2 = tick_once(thesis_case(2), on).force_device_N;
  const Vec3 F4 = tick_once(thesis_case(4), on).force_device_N;
  EXPECT_GT(F2.norm(), 0.1);
  EXPECT_LT((F4 - 2.0 * F2).norm(), 1e-9);

  const Vec3 rm = on_circle(0.5, 60.0);
  const Joints off = pose_q(rm, radial(0.2) + Vec3(0, 0, 0.2));
  const Vec3 G2 = tick_once(thesis_case(2), off).force_device_N;
  const Vec3 G4 = tick_once(thesis_case(4), off).force_device_N;
  EXPECT_NEAR(G4.dot(tangent(0.5)), 2.0 * G2.dot(tangent(0.5)), 1e-9);
  EXPECT_NEAR(G4.dot(radial(0.5)), G2.dot(radial(0.5)), 1e-9);
  const Vec3 x_v = kL * radial(0.5);
  EXPECT_GT(angle_between(G4, x_v - rm), angle_between(G2, x_v - rm));
  EXPECT_GT(G4.norm(), G2.norm());
}

// Case 6 on the sphere, geometric error: the force is tangent to the sphere
// and points toward X(theta_R), for any misalignment.
TEST(ThesisClaims, Case6OnTheSphereGeometricForcePointsTowardXThetaR) {
  ControllerParams p = thesis_case(6);
  p.error = ErrorFormulation::kGeometric;
  int checked = 0;
  for (const Vec3& dir : {Vec3(1, 0.2, -0.3), Vec3(-0.4, 1, 0.5),
                          Vec3(0.3, -0.6, 0.8), Vec3(-0.8, -0.2, -0.3)}) {
    const Vec3 u = dir.normalized();
    const Vec3 rm = kL * u;
    for (const Vec3& tilt : {Vec3(0.3, 0, 0), Vec3(0, -0.25, 0.1),
                             Vec3(0.1, 0.2, -0.3)}) {
      const Vec3 a = (u + tilt).normalized();  // stylus axis
      const ControlOutput out = tick_once(p, pose_q(rm, a));
      const Vec3 F = out.force_device_N;
      const Vec3 x_r = kL * a;  // X(theta_R): the link along the stylus
      EXPECT_LT((out.x_r_mm - x_r).norm(), 1e-9);
      EXPECT_NEAR(F.dot(u), 0.0, 1e-9 * F.norm());  // along the sphere
      EXPECT_GT(F.dot(x_r - rm), 0.0);
      // and in the plane of the pivot, the RM and X(theta_R): it turns the
      // link the shortest way onto the stylus
      EXPECT_NEAR(F.dot(u.cross(a).normalized()), 0.0, 1e-9 * F.norm());
      ++checked;
    }
  }
  EXPECT_EQ(checked, 12);
}

// Case 6 with the thesis's error (eq. 3.36-3.37): an azimuth misalignment
// pulls toward X(theta_R) everywhere, but a polar one only where
// cos(theta_V1) < 0. Eq. 3.36 puts d theta2 in the theta_y row, while
// J_V's theta2 column turns about (sin theta1, -cos theta1, 0) (eq. 3.31);
// the two agree in sign only for cos theta1 < 0. docs/errata.md.
TEST(ThesisClaims, Case6ThesisErrorPullsTowardXThetaROnlyWhereCosTheta1Neg) {
  const ControllerParams p = thesis_case(6);
  for (double t1 : {-2.5, -1.0, 0.0, 1.0, 2.5}) {
    const double t2 = 2.0;  // polar angle from -z
    auto dir = [](double a1, double a2) {
      return Vec3(std::cos(a1) * std::sin(a2), std::sin(a1) * std::sin(a2),
                  -std::cos(a2));
    };
    const Vec3 rm = kL * dir(t1, t2);
    // azimuth misalignment
    const Vec3 a_az = dir(t1 + 0.3, t2);
    const Vec3 F_az = tick_once(p, pose_q(rm, a_az)).force_device_N;
    EXPECT_GT(F_az.dot(kL * a_az - rm), 0.0) << "theta1 " << t1;
    // polar misalignment
    const Vec3 a_po = dir(t1, t2 + 0.3);
    const Vec3 F_po = tick_once(p, pose_q(rm, a_po)).force_device_N;
    const double toward = F_po.dot(kL * a_po - rm);
    if (std::cos(t1) < -0.1) {
      EXPECT_GT(toward, 0.0) << "theta1 " << t1;
    } else if (std::cos(t1) > 0.1) {
      EXPECT_LT(toward, 0.0) << "theta1 " << t1;
    }
  }
}

// ------------------------------------------------------- units (§2)

// Case 1's force is the same in mm and m: no orientation error enters. Case
// 2's on-path force scales as L/(L^2 + 1), so it differs by ~400x.
TEST(Units, LengthScaleChangesOnlyTheProjection) {
  ControllerParams mm = thesis_case(1);
  ControllerParams m = mm;
  m.length_unit_mm = 1000.0;
  const Joints off = pose_q(on_circle(0.3, 60.0, 4.0), Vec3(0.3, 0, 1));
  EXPECT_LT((tick_once(m, off).force_device_N -
             tick_once(mm, off).force_device_N)
                .norm(),
            1e-12);

  ControllerParams mm2 = thesis_case(2);
  ControllerParams m2 = mm2;
  m2.length_unit_mm = 1000.0;
  const double d = 0.2;
  const Joints on = pose_q(on_circle(0.3), radial(0.3 - d));
  const double K_Nmm = thesis_orientation_gain(0.5, kL);
  const double F_mm = tick_once(mm2, on).force_device_N.norm();
  const double F_m = tick_once(m2, on).force_device_N.norm();
  const double L_m = kL / 1000.0;
  EXPECT_NEAR(F_mm, K_Nmm * d * kL / (kL * kL + 1.0), 1e-9);
  EXPECT_NEAR(F_m, (K_Nmm / 1000.0) * d * L_m / (L_m * L_m + 1.0), 1e-12);
  EXPECT_GT(F_mm / F_m, 300.0);
}

// ------------------------------------------- torques and saturation

// tau = J_r^T F by virtual work, checked with finite differences of the
// forward kinematics instead of the Jacobian
TEST(Torques, AreTheVirtualWorkOfTheForce) {
  const OmniParams omni;
  ControllerParams p = thesis_case(2);
  testing::JointSampler sampler(11);
  for (int k = 0; k < 50; ++k) {
    const Joints q = sampler.next_within(omni);
    const ControlOutput out = tick_once(p, q);
    const Vec3 F = out.force_device_N;
    for (int i = 0; i < 3; ++i) {
      const double h = 1e-6;
      Joints qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      const Vec3 dp_mm = (base_to_device_mm(omni, omni_fk(omni, qp).p_base_m) -
                          base_to_device_mm(omni, omni_fk(omni, qm).p_base_m)) /
                         (2 * h);
      const double tau = F.dot(dp_mm) / kMmPerM;  // N mm -> N m
      EXPECT_NEAR(out.tau_dh_Nm[i], tau, 1e-7);
    }
    // motor torques do the same work for any joint velocity
    const Joints qd = sampler.next();
    const Joints t0 = dh_to_device_joints(q);
    const Joints t1 = dh_to_device_joints(q + 1e-6 * qd);
    const Vec3 td = (t1 - t0).head<3>() / 1e-6;
    EXPECT_NEAR(out.tau_motor_Nm.dot(td), out.tau_dh_Nm.dot(qd.head<3>()),
                1e-6);
  }
}

TEST(Saturation, ForceIsClampedAlongItsDirection) {
  ControllerParams p = thesis_case(1);
  p.force_limit_N = 3.3;
  p.omni.motor_torque_limit_Nm = {10, 10, 10};
  const ControlOutput out =
      tick_once(p, pose_q(on_circle(0.4, 120.0, 30.0), Vec3(0, 0, 1)));
  EXPECT_NEAR(out.force_device_N.norm(), 3.3, 1e-12);
  EXPECT_LT(angle_between(out.force_device_N, out.f_motion.head<3>()), 1e-12);
  EXPECT_GT(out.f_motion.head<3>().norm(), 3.3);
  EXPECT_TRUE(out.status & kStatusForceSaturated);
  EXPECT_FALSE(out.status & kStatusTorqueSaturated);
}

TEST(Saturation, MotorTorquesStayWithinTheirLimits) {
  const OmniParams omni;
  ControllerParams p;  // device limits
  p.gains.k_pos_N_per_mm = 5.0;
  testing::JointSampler sampler(5);
  int saturated = 0;
  for (int k = 0; k < 200; ++k) {
    const ControlOutput out = tick_once(p, sampler.next_within(omni));
    EXPECT_LE(out.force_device_N.norm(), omni.max_force_N + 1e-12);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(out.tau_motor_Nm[i]),
                omni.motor_torque_limit_Nm[static_cast<std::size_t>(i)] +
                    1e-12);
    }
    // the force still points where f_motion does
    if (out.force_device_N.norm() > 1e-9) {
      EXPECT_LT(angle_between(out.force_device_N, out.f_motion.head<3>()),
                1e-9);
    }
    if (out.status & kStatusTorqueSaturated) ++saturated;
  }
  EXPECT_GT(saturated, 0);  // the test did exercise the torque clamp
}

// ---------------------------------------- faults and singular poses

TEST(Faults, NonFiniteJointAnglesGiveZeroForceAndAFault) {
  Controller c(thesis_case(2));
  ControlOutput out;
  const Joints good = pose_q(on_circle(0.4, 60.0), Vec3(0.3, 0.1, 1));
  c.tick(good, &out);
  EXPECT_GT(out.force_device_N.norm(), 0.1);
  for (double bad : {kNaN, std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()}) {
    for (int i = 0; i < 6; ++i) {
      Joints q = good;
      q[i] = bad;
      const ControlStatus st = c.tick(q, &out);
      EXPECT_EQ(st, kStatusInvalidInput);
      EXPECT_TRUE(is_fault(st));
      EXPECT_EQ(out.force_device_N, Vec3::Zero());
      EXPECT_EQ(out.tau_motor_Nm, Vec3::Zero());
      EXPECT_EQ(out.tau_dh_Nm, Vec3::Zero());
    }
  }
  // and recovers on the next good sample, with the same force as before
  ControlOutput again;
  Controller fresh(thesis_case(2));
  fresh.tick(good, &again);
  c.tick(good, &out);
  EXPECT_FALSE(is_fault(out.status));
  EXPECT_LT((out.force_device_N - again.force_device_N).norm(), 1e-9);
}

// A force so large that |F|^2 overflows (K_pos 1e154 N/mm, 10 mm off the
// circle: |F| ~ 1e155 N) is a numerical fault with zero force, not a
// saturation: F / |F| was 0 and the zero force was reported as
// force_saturated (issue 17). Just below the overflow it saturates properly.
TEST(Faults, AnOverflowingForceIsANumericalFaultNotASaturation) {
  const Joints q = pose_q(on_circle(0.4, 60.0), Vec3(0.3, 0.1, 1));
  ControllerParams p = thesis_case(1);
  p.force_limit_N = 3.3;
  p.omni.motor_torque_limit_Nm = {10, 10, 10};
  p.gains.k_pos_N_per_mm = 1e154;
  Controller c(p);
  ControlOutput out;
  const ControlStatus st = c.tick(q, &out);
  EXPECT_TRUE(st & kStatusNumericalFault) << st;
  EXPECT_FALSE(st & kStatusForceSaturated) << st;
  EXPECT_FALSE(st & kStatusTorqueSaturated) << st;
  EXPECT_TRUE(is_fault(st));
  EXPECT_EQ(out.status, st);
  EXPECT_EQ(out.force_device_N, Vec3::Zero());
  EXPECT_EQ(out.force_base_N, Vec3::Zero());
  EXPECT_EQ(out.tau_dh_Nm, Vec3::Zero());
  EXPECT_EQ(out.tau_motor_Nm, Vec3::Zero());

  p.gains.k_pos_N_per_mm = 1e150;  // |F| ~ 1e151 N: |F|^2 still finite
  const ControlOutput big = tick_once(p, q);
  EXPECT_FALSE(is_fault(big.status));
  EXPECT_TRUE(big.status & kStatusForceSaturated);
  EXPECT_GT(big.force_device_N.norm(), 0.0);
  EXPECT_LE(big.force_device_N.norm(), 3.3 + 1e-12);
  EXPECT_LT(angle_between(big.force_device_N, big.f_motion.head<3>()), 1e-9);
}

// Found by tests/fuzz/controller_tick_fuzz.cc: a force limit of 6e-161 N
// was accepted, its square underflowed, and the commanded force came out
// above the limit. Such limits are refused; the smallest accepted one holds.
TEST(Saturation, ATinyForceLimitIsRefusedAndTheSmallestHolds) {
  ControllerParams p = thesis_case(1);
  p.force_limit_N = 5.95124e-161;
  EXPECT_THROW(Controller c(p), std::invalid_argument);
  p.force_limit_N = 0.5 * kMinForceLimit_N;
  EXPECT_THROW(Controller c(p), std::invalid_argument);
  p.force_limit_N = kMinForceLimit_N;
  const ControlOutput out =
      tick_once(p, pose_q(on_circle(0.4, 120.0, 30.0), Vec3(0, 0, 1)));
  EXPECT_TRUE(out.status & kStatusForceSaturated);
  EXPECT_LE(out.force_device_N.norm(), kMinForceLimit_N * (1.0 + 1e-12));
  EXPECT_GT(out.force_device_N.norm(), 0.0);
}

void expect_finite(const ControlOutput& out) {
  EXPECT_TRUE(out.f_motion.allFinite());
  EXPECT_TRUE(out.e.allFinite());
  EXPECT_TRUE(out.force_device_N.allFinite());
  EXPECT_TRUE(out.tau_motor_Nm.allFinite());
  EXPECT_TRUE(out.theta_v.allFinite());
  EXPECT_TRUE(out.theta_r.allFinite());
  EXPECT_FALSE(is_fault(out.status));
}

TEST(Singular, RmAtThePivotIsFiniteAndReported) {
  for (int n : {2, 6}) {
    ControllerParams p = thesis_case(n);
    // the pivot is the device origin: the home pose q = 0
    Controller c(p);
    ControlOutput out;
    c.tick(Joints::Zero(), &out);
    expect_finite(out);
    EXPECT_TRUE(out.status & kStatusRmAtPivot) << n;
  }
}

TEST(Singular, SpherePolesAreFiniteAndReported) {
  for (double sign : {-1.0, 1.0}) {
    for (ErrorFormulation f :
         {ErrorFormulation::kThesis, ErrorFormulation::kGeometric}) {
      ControllerParams p = thesis_case(6);
      p.error = f;
      Controller c(p);
      ControlOutput out;
      // on the pole axis (device z) with the stylus along it too
      c.tick(pose_q(Vec3(0, 0, sign * 60.0), Vec3(0.0, 0.0, 1.0)), &out);
      expect_finite(out);
      EXPECT_TRUE(out.status & kStatusVmSingular);
      // the pull onto the sphere survives the singularity
      EXPECT_NEAR(out.f_motion.head<3>().dot(Vec3(0, 0, sign)), -0.5 * 10.0,
                  1e-6);
    }
  }
}

TEST(Singular, CircleWithStylusAlongItsNormalIsReported) {
  ControllerParams p = thesis_case(2);
  Controller c(p);
  ControlOutput out;
  c.tick(pose_q(on_circle(0.3, 50.0, 0.0), Vec3(0, 0, 1)), &out);
  expect_finite(out);
  EXPECT_TRUE(out.status & kStatusOrientationDegenerate);
}

// ------------------------------------------------------------ wrap

// The stylus turning through theta_R = +-pi while the RM sits at theta_V
// near pi: the orientation error stays small and continuous (wrapped), and
// so does the force.
TEST(Wrap, OrientationErrorCrossingPiStaysContinuous) {
  ControllerParams p = thesis_case(2);
  Controller c(p);
  ControlOutput out;
  const double a = kPi - 0.05;  // RM position angle
  double last = 0;
  bool first = true;
  for (double b = kPi - 0.2; b < kPi + 0.2; b += 0.01) {
    c.tick(pose_q(on_circle(a), radial(b)), &out);
    const double e = out.e[5];
    EXPECT_LT(std::abs(e), 0.25 + 1e-9);
    EXPECT_NEAR(e, wrap_angle(a - b), 1e-9);
    if (!first) {
      EXPECT_LT(std::abs(e - last), 0.011);
    }
    last = e;
    first = false;
  }
}

// --------------------------------------------------- warm start, e_dot

TEST(Placement, GaussNewtonAndClosedFormGiveTheSameForce) {
  const OmniParams omni;
  testing::JointSampler sampler(3);
  for (int n : {1, 2, 5, 6}) {
    ControllerParams gn = thesis_case(n);
    ControllerParams cf = gn;
    cf.placement = PlacementMethod::kClosedForm;
    Controller a(gn), b(cf);
    ControlOutput oa, ob;
    for (int k = 0; k < 100; ++k) {
      const Joints q = sampler.next_within(omni);
      a.tick(q, &oa);
      b.tick(q, &ob);
      EXPECT_LT((oa.x_v_mm - ob.x_v_mm).norm(), 1e-7) << "case " << n;
      EXPECT_LT((oa.f_motion - ob.f_motion).norm(), 1e-6) << "case " << n;
    }
  }
}

// e_dot from the backward difference: the RM moving radially outward at
// v mm/s has e_x' = -v along the radius once the filter has settled
TEST(Velocity, ErrorRateFollowsTheMotion) {
  ControllerParams p = thesis_case(1);
  p.gains.k_vel_Ns_per_mm = 0.001;
  Controller c(p);
  ControlOutput out;
  const double v = 20.0;  // mm/s
  for (int k = 0; k < 200; ++k) {
    const double r = 55.0 + v * k * p.servo_period_s;
    c.tick(pose_q(on_circle(0.6, r), Vec3(0, 0, 1)), &out);
  }
  EXPECT_NEAR(out.e_dot.head<3>().dot(radial(0.6)), -v, 0.02 * v);
  // damping adds K_v e_dot to the pull
  EXPECT_NEAR(out.f_motion.head<3>().dot(radial(0.6)),
              0.5 * out.e.head<3>().dot(radial(0.6)) - 0.001 * v, 1e-3);
}

// ---------------------------------------------------------- surface

// The plane z = -50 mm (device frame) under the home pose: with the stylus
// along +z at the origin the probe tip (50 mm back along the stylus) just
// touches it.
ControllerParams surface_params(double mu, bool unilateral) {
  ControllerParams p;
  p.vm.kind = VmKind::kSurface;
  p.vm.pivot_mm = Vec3(0, 0, -kL);
  p.vm.friction_mu = mu;
  p.vm.unilateral = unilateral;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, kL);
  p.placement_options.weights = Vec6::Ones();
  p.force_limit_N = 1e9;
  p.omni.motor_torque_limit_Nm = {1e9, 1e9, 1e9};
  return p;
}

TEST(Surface, TipOnThePlaneFeelsNoForce) {
  Controller c(surface_params(0.0, false));
  ControlOutput out;
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(20, -10, 0), Vec3(-15, 25, 0)}) {
    c.tick(pose_q(p, Vec3(0, 0, 1)), &out);
    EXPECT_LT(out.force_device_N.norm(), 1e-6) << p.transpose();
  }
  // tilted stylus, tip still on the plane: still free
  const Vec3 a = Vec3(0.3, -0.2, 1).normalized();
  c.tick(pose_q(Vec3(5, 5, -kL) + kL * a, a), &out);
  EXPECT_LT(out.force_device_N.norm(), 1e-6);
}

TEST(Surface, PressingIntoThePlanePushesBackAlongTheNormal) {
  Controller c(surface_params(0.0, false));
  ControlOutput out;
  c.tick(pose_q(Vec3(10, 5, -8), Vec3(0, 0, 1)), &out);  // tip 8 mm under
  const Vec3 F = out.force_device_N;
  EXPECT_GT(F.z(), 0.5);
  EXPECT_LT(angle_between(F, Vec3::UnitZ()), 1e-3);
}

TEST(Surface, StickingContactHoldsThenSlides) {
  Controller c(surface_params(0.5, false));
  ControlOutput out;
  // touch down at the origin
  c.tick(pose_q(Vec3(0, 0, 0), Vec3(0, 0, 1)), &out);
  const Vec3 contact0 = out.x_v_mm - kL * Vec3::UnitZ();
  EXPECT_LT((contact0 - Vec3(0, 0, -kL)).norm(), 1e-6);
  // press down and drag a little: inside the friction cone, it sticks
  c.tick(pose_q(Vec3(1.0, 0, -6.0), Vec3(0, 0, 1)), &out);
  EXPECT_FALSE(out.status & kStatusContactSliding);
  EXPECT_NEAR(out.theta_v[0], 0.0, 1e-12);
  EXPECT_NEAR(out.theta_v[1], 0.0, 1e-12);
  EXPECT_GT(out.force_device_N.dot(Vec3(-1, 0, 0)), 0.0);  // holds back
  // drag far with a light touch: the cone is left, the contact moves
  c.tick(pose_q(Vec3(25.0, 0, -0.5), Vec3(0, 0, 1)), &out);
  EXPECT_TRUE(out.status & kStatusContactSliding);
  EXPECT_GT(out.theta_v[0], 10.0);
}

TEST(Surface, UnilateralContactLetsGo) {
  Controller c(surface_params(0.0, true));
  ControlOutput out;
  c.tick(pose_q(Vec3(0, 0, 10.0), Vec3(0, 0, 1)), &out);  // tip 10 mm above
  EXPECT_TRUE(out.status & kStatusContactOpen);
  EXPECT_EQ(out.force_device_N, Vec3::Zero());
  Controller bilateral(surface_params(0.0, false));
  bilateral.tick(pose_q(Vec3(0, 0, 10.0), Vec3(0, 0, 1)), &out);
  EXPECT_LT(out.force_device_N.z(), -0.5);  // held on the plane
}

}  // namespace
}  // namespace vmh
