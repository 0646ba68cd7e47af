// thesis/law_prediction.cc: the law at a pose by the rigid-rotation J_V
// and closed-form placement, checked against hand-derived closed forms and
// against the controller (eq. 3.27/3.31's angle Jacobians, its own
// placement and projection), which it must agree with to rounding.
#include "thesis/law_prediction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh::thesis {
namespace {

ControllerParams circle_params() {
  ControllerParams p;
  p.vm.kind = VmKind::kCircle;
  p.vm.pivot_mm = Vec3(0.0, -60.0, -90.0);
  p.vm.length_mm = 50.0;
  p.gains.k_pos_N_per_mm = 0.5;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  p.placement = PlacementMethod::kClosedForm;
  return p;
}

// a pose of the device, its wrist centre (mm) and stylus axis, device frame
struct Pose {
  Joints q;
  Vec3 p_mm;
  Vec3 axis;
};
Pose pose_of(const OmniParams& omni, const Joints& q) {
  const OmniPose fk = omni_fk(omni, q);
  return {q, base_to_device_mm(omni, fk.p_base_m),
          base_to_device_vector(fk.R_base.col(2))};
}

// Position only: F = K_pos (X_V - p), of size K_pos d with d the distance
// from the circle, sqrt((rho - L)^2 + z^2), and no tangential part.
TEST(LawPrediction, CirclePositionOnlyIsKposTimesTheDistance) {
  ControllerParams p = circle_params();
  p.gains.k_ornt_Nmm_per_rad = 0.0;
  for (const Vec3& off : {Vec3(70, 5, 3), Vec3(-20, 30, -8), Vec3(10, -44, 12)}) {
    const Vec3 pos = p.vm.pivot_mm + off;
    const LawPrediction lp =
        predict_static_law(p, pos, Vec3(0, 0.6, 0.8), Joints::Zero());
    ASSERT_TRUE(lp.available) << lp.reason;
    const double rho = std::hypot(off.x(), off.y());
    const double d = std::hypot(rho - 50.0, off.z());
    EXPECT_NEAR(lp.force_N.norm(), 0.5 * d, 1e-12);
    const Vec3 t = Vec3::UnitZ().cross(Vec3(off.x(), off.y(), 0)).normalized();
    EXPECT_NEAR(lp.force_N.dot(t), 0.0, 1e-12);
    EXPECT_LT((lp.x_v_mm - pos).cross(lp.force_N).norm(), 1e-12);
  }
}

// On the circle with the stylus turned by delta in its plane: g = (0, K_o
// delta n), j = (L t, n), so F = -L t K_o delta / (L^2 + 1), along the path
// toward X(theta_R), |F| = L K_o |delta| / (L^2 + 1) (about pi |delta| N
// for K_o = 0.5 x 2 pi L, the thesis's case 2).
TEST(LawPrediction, CircleOnThePathIsTheTangentialClosedForm) {
  const ControllerParams p = circle_params();
  const double L = 50.0, Ko = p.gains.k_ornt_Nmm_per_rad;
  for (const double phi : {-2.0, -0.4, 0.3, 1.9}) {
    for (const double delta : {-0.5, -0.1, 0.2, 0.7}) {
      const Vec3 pos = p.vm.pivot_mm + L * Vec3(std::cos(phi), std::sin(phi), 0);
      const Vec3 axis =
          Vec3(std::cos(phi + delta), std::sin(phi + delta), 0.4).normalized();
      const LawPrediction lp = predict_static_law(p, pos, axis, Joints::Zero());
      ASSERT_TRUE(lp.available) << lp.reason;
      EXPECT_NEAR(lp.force_N.norm(), L * Ko * std::abs(delta) / (L * L + 1),
                  1e-9);
      const Vec3 t(-std::sin(phi), std::cos(phi), 0.0);
      EXPECT_NEAR(std::abs(lp.force_N.dot(t)), lp.force_N.norm(), 1e-9);
      EXPECT_GT(lp.force_N.dot(lp.x_r_mm - lp.x_v_mm), 0.0);
    }
  }
}

// The controller with closed-form placement, on its first tick (e_dot = 0)
// and exact readings, commands the predicted force: two implementations of
// eq. 3.11 (angle Jacobians of eq. 3.27/3.31 and its projector code against
// the rigid rotations and a generic solve), for the circle and the sphere
// under both error formulations, unlimited and with the default limits; the
// line slider's hook (the foot of the perpendicular, J_V = [y; 0]) the same.
TEST(LawPrediction, AgreesWithTheControllerOnRandomPoses) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0, limited = 0;
  for (const VmKind kind : {VmKind::kCircle, VmKind::kSphere, VmKind::kLine}) {
    for (const ErrorFormulation err :
         {ErrorFormulation::kThesis, ErrorFormulation::kGeometric}) {
      for (const bool limits : {false, true}) {
        ControllerParams p = circle_params();
        p.vm.kind = kind;
        p.error = err;
        p.vm.R_pivot = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized())
                           .toRotationMatrix();
        if (!limits) {
          p.force_limit_N = 1e9;
          p.omni.motor_torque_limit_Nm = {1e9, 1e9, 1e9};
        }
        for (int i = 0; i < 60; ++i) {
          Joints q;
          q << 0.6 * u(rng), 0.3 + 0.4 * u(rng), 0.4 * u(rng), 1.5 * u(rng),
              -0.5 + 0.8 * u(rng), 1.5 * u(rng);
          const Pose ps = pose_of(p.omni, q);
          const LawPrediction lp = predict_static_law(p, ps.p_mm, ps.axis, q);
          if (!lp.available) continue;
          Controller c(p);
          ControlOutput out;
          c.tick(q, &out);
          if (is_fault(out.status) ||
              (out.status & (kStatusVmSingular | kStatusRmAtPivot |
                             kStatusOrientationDegenerate))) {
            continue;
          }
          ++compared;
          limited += lp.limited ? 1 : 0;
          EXPECT_EQ(lp.limited, (out.status & (kStatusForceSaturated |
                                               kStatusTorqueSaturated)) != 0);
          EXPECT_LT((out.force_device_N - lp.force_limited_N).norm(),
                    1e-9 * std::max(1.0, lp.force_N.norm()))
              << "kind " << static_cast<int>(kind) << " error "
              << static_cast<int>(err) << " pose " << i << ": controller "
              << out.force_device_N.transpose() << ", predicted "
              << lp.force_limited_N.transpose();
          EXPECT_LT((out.x_v_mm - lp.x_v_mm).norm(), 1e-9);
          EXPECT_LT((out.x_r_mm - lp.x_r_mm).norm(), 1e-9);
        }
      }
    }
  }
  EXPECT_GT(compared, 300);
  EXPECT_GT(limited, 20);  // the limits were exercised
}

// The line, by hand: K_pos times the offset, normal to the line, whatever
// the stylus; X(theta_R) = X(theta_V)
TEST(LawPrediction, LineIsTheSpringToTheLineAlone) {
  ControllerParams p = circle_params();
  p.vm.kind = VmKind::kLine;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  p.force_limit_N = 1e9;
  p.omni.motor_torque_limit_Nm = {1e9, 1e9, 1e9};
  for (const ErrorFormulation err :
       {ErrorFormulation::kThesis, ErrorFormulation::kGeometric}) {
    p.error = err;
    // 7 mm off the line (device y through the pivot), 30 mm along it
    const Vec3 at = p.vm.pivot_mm + Vec3(-7.0, 30.0, 4.0);
    for (const Vec3& axis : {Vec3(0, 0, 1), Vec3(0.6, 0.0, 0.8),
                             Vec3(0.0, 0.8, 0.6)}) {
      const LawPrediction lp =
          predict_static_law(p, at, axis, Joints::Zero());
      ASSERT_TRUE(lp.available) << lp.reason;
      EXPECT_LT((lp.x_v_mm - (p.vm.pivot_mm + Vec3(0, 30, 0))).norm(), 1e-12);
      EXPECT_LT((lp.x_r_mm - lp.x_v_mm).norm(), 1e-12);
      EXPECT_LT((lp.force_N - p.gains.k_pos_N_per_mm * Vec3(7.0, 0.0, -4.0))
                    .norm(),
                1e-12);
    }
  }
}

TEST(LawPrediction, NoPredictionWhereThePlacementIsUndefined) {
  const ControllerParams p = circle_params();
  // on the circle's axis
  const LawPrediction a = predict_static_law(
      p, p.vm.pivot_mm + Vec3(0, 0, 20), Vec3(0, 1, 0), Joints::Zero());
  EXPECT_FALSE(a.available);
  EXPECT_NE(a.reason.find("pivot axis"), std::string::npos) << a.reason;
  // a surface VM has no closed-form placement here
  ControllerParams s = p;
  s.vm.kind = VmKind::kSurface;
  EXPECT_FALSE(predict_static_law(s, Vec3(0, 0, 0), Vec3(0, 0, 1),
                                  Joints::Zero())
                   .available);
  // non-finite input
  EXPECT_FALSE(predict_static_law(p, Vec3(std::nan(""), 0, 0), Vec3(0, 0, 1),
                                  Joints::Zero())
                   .available);
}

}  // namespace
}  // namespace vmh::thesis
