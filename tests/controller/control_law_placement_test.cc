// Checks of controller/control_law's placement (eq. 3.15-3.16) against
// routes that do not share its code: the VMs' closed-form placements
// (nearest / aligned), first-order optimality of the weighted cost, brute
// comparisons with perturbed angles, and the residual's definition.
#include "controller/control_law.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/virtual_mechanism.h"
#include "controller/vm_circle.h"
#include "controller/vm_line.h"
#include "controller/vm_registry.h"
#include "controller/vm_sphere.h"
#include "controller/vm_surface.h"
#include "tests/support/random_vm.h"
#include "tests/support/vm_cases.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;

using testing::Case;
using testing::cases;
using testing::random_theta;
using testing::random_unit;
using testing::turned_mount;
using testing::uniform;

using Eigen::MatrixXd;
using Eigen::VectorXd;

// a dynamic copy: the checks run on plain dynamic matrices (GCC 12 warns
// falsely inside Eigen reductions over the fixed-capacity VmJacobian)
MatrixXd dynamic_copy(const VmJacobian& J) { return J; }

// the cost r^T W r, from the residual
double cost_at(const VirtualMechanism& vm, const RmPose& rm, const Vec6& w,
               const VmAngles& theta) {
  const Vec6 r = placement_residual(vm, rm, theta);
  return r.dot(w.cwiseProduct(r));
}

// |J^T W r| relative to |J| |W r|: zero at a stationary point of r^T W r
// (with equal orientation weights J_rot^T r_o is exactly half the gradient
// of |r_o|^2, so this is first-order optimality of the cost)
double optimality(const VirtualMechanism& vm, const RmPose& rm, const Vec6& w,
                  const VmAngles& theta) {
  VmJacobian J;
  vm.jacobian(theta, &J);
  const Vec6 Wr = w.cwiseProduct(placement_residual(vm, rm, theta));
  return (dynamic_copy(J).transpose() * Wr).norm() / (J.norm() * Wr.norm() + 1e-300);
}

// a stylus standing above a surface VM's plane, more or less upright, the
// wrist centre within L of the mount along the plane and 0.3-2 L above it
RmPose random_pose_above(const SurfaceVm& vm, std::mt19937* rng) {
  const double L = vm.length();
  const Vec3 o = vm.mount().origin, n = vm.normal();
  const Vec3 axis = (n + 0.7 * random_unit(rng)).normalized();
  const Vec3 p = o + uniform(rng, -L, L) * vm.mount().R.col(0) +
                 uniform(rng, -L, L) * vm.mount().R.col(1) +
                 uniform(rng, 0.3, 2.0) * L * n;
  return RmPose{p, axis};
}

Vec6 position_weights() { return (Vec6() << 1, 1, 1, 0, 0, 0).finished(); }
Vec6 orientation_weights() { return (Vec6() << 0, 0, 0, 1, 1, 1).finished(); }

// identity: the placement residual is p - X_V and, in the orientation rows,
// the rotation vector carrying the link axis onto the stylus axis
TEST(PlacementResidual, PositionAndRotationCarryingLinkOntoStylus) {
  std::mt19937 rng(200);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere,
                              VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    for (int k = 0; k < 100; ++k) {
      const VmAngles theta = random_theta(vm, &rng);
      RmPose rm{vm.mount().origin + vm.length() * random_unit(&rng),
                random_unit(&rng)};
      const Vec6 r = placement_residual(vm, rm, theta);
      const VmPose pose = vm.pose(theta);
      EXPECT_LE((r.head<3>() - (rm.p - pose.p)).norm(), 1e-12 * vm.length());
      if (vm.kind() != VmKind::kCircle) {
        const Vec3 o = r.tail<3>();
        EXPECT_LE((Eigen::AngleAxisd(o.norm(), o.normalized()) * pose.axis -
                   rm.axis)
                      .norm(),
                  1e-12)
            << c.name;
      }
    }
  }
}

// An RM position where Gauss-Newton under W_p contracts at a rate
// |1 - d/L| <= 1/2: d, the distance from the pivot (sphere) or the in-plane
// distance (circle, which also gets an out-of-plane offset), in [0.5, 1.5] L
Vec3 rm_position(const VirtualMechanism& vm, std::mt19937* rng) {
  const double L = vm.length();
  const double d = uniform(rng, 0.5, 1.5) * L;
  if (vm.kind() == VmKind::kCircle) {
    const double a = uniform(rng, -kPi, kPi);
    const Mat3& R = vm.mount().R;
    return vm.mount().origin + d * (std::cos(a) * R.col(0) + std::sin(a) * R.col(1)) +
           uniform(rng, -L, L) * R.col(2);
  }
  return vm.mount().origin + d * random_unit(rng);
}

// one plain Gauss-Newton step at theta, computed here: the minimum-norm
// least-squares solution of W^(1/2) J delta = W^(1/2) r (Jacobi SVD)
VectorXd plain_gauss_newton_step(const VirtualMechanism& vm, const RmPose& rm,
                                 const Vec6& w, const VmAngles& theta) {
  VmJacobian J;
  vm.jacobian(theta, &J);
  const MatrixXd B = w.cwiseSqrt().asDiagonal() * dynamic_copy(J);
  const VectorXd b =
      w.cwiseSqrt().asDiagonal() * VectorXd(placement_residual(vm, rm, theta));
  Eigen::JacobiSVD<MatrixXd> svd(B, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-12);
  return svd.solve(b);
}

// identity: with W_p the Gauss-Newton placement reaches the closed-form
// nearest() point (circle, sphere) from random starts. Where the iteration
// contracts at a rate <= 1/2 (as here), a last step below the documented
// tolerance leaves at most that much: allow 2 tolerances (x L), or 1e-9 L
// if that is larger.
TEST(PlaceGaussNewton, PositionWeightGivesNearest) {
  std::mt19937 rng(201);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    PlacementOptions opt;
    opt.weights = position_weights();
    int not_converged = 0;
    double worst = 0;
    for (int k = 0; k < 500; ++k) {
      const RmPose rm{rm_position(vm, &rng), random_unit(&rng)};
      VmAngles theta = random_theta(vm, &rng);
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      if (!res.converged) ++not_converged;
      VmAngles closed = vm.zero_angles();
      ASSERT_TRUE(vm.nearest(rm, &closed));
      worst = std::max(worst, (vm.pose(theta).p - vm.pose(closed).p).norm());
      EXPECT_NEAR(res.cost, cost_at(vm, rm, opt.weights, theta),
                  1e-12 * L * L);
    }
    EXPECT_EQ(not_converged, 0) << c.name;
    EXPECT_LE(worst, std::max(1e-9, 2 * opt.tolerance) * L)
        << c.name << ": worst |X_GN - X_nearest| / L = " << worst / L;
  }
}

// identity: where place_gauss_newton reports convergence, one more plain
// Gauss-Newton step (computed here) is below the documented tolerance
// ("stop when max |delta theta| falls below this"), within a factor 10
TEST(PlaceGaussNewton, ReturnedPointMeetsTheStepTolerance) {
  std::mt19937 rng(208);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    for (int blend = 0; blend < 2; ++blend) {
      PlacementOptions opt;
      opt.weights = position_weights();
      if (blend) opt.weights.tail<3>().setConstant(L * L);
      opt.max_iterations = 1000;
      double worst = 0;
      for (int k = 0; k < 500; ++k) {
        const RmPose rm{rm_position(vm, &rng), random_unit(&rng)};
        VmAngles theta = random_theta(vm, &rng);
        if (!place_gauss_newton(vm, rm, opt, JointMask{0}, &theta).converged)
          continue;  // counted by the other tests
        worst = std::max(worst, plain_gauss_newton_step(vm, rm, opt.weights,
                                                        theta)
                                    .cwiseAbs()
                                    .maxCoeff());
      }
      EXPECT_LE(worst, 10 * opt.tolerance)
          << c.name << " blend " << blend << ": worst next step " << worst;
    }
  }
}

// identity: started at the closed form, W_p placement confirms it at once
TEST(PlaceGaussNewton, SeededAtTheClosedFormStopsAtOnce) {
  std::mt19937 rng(202);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    PlacementOptions opt;
    opt.weights = position_weights();
    for (int k = 0; k < 100; ++k) {
      const RmPose rm{vm.mount().origin +
                          uniform(&rng, 0.1, 3.0) * L * random_unit(&rng),
                      random_unit(&rng)};
      VmAngles theta = random_theta(vm, &rng);
      ASSERT_TRUE(vm.nearest(rm, &theta));
      const Vec3 p0 = vm.pose(theta).p;
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      EXPECT_TRUE(res.converged) << c.name;
      EXPECT_LE(res.iterations, 2) << c.name;
      EXPECT_LE((vm.pose(theta).p - p0).norm(), 1e-9 * L) << c.name;
    }
  }
}

// identity: with W_o the placement turns the link onto aligned()'s axis
// (sphere: the stylus axis; circle: its normalised in-plane projection)
TEST(PlaceGaussNewton, OrientationWeightGivesAligned) {
  std::mt19937 rng(203);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    PlacementOptions opt;
    opt.weights = orientation_weights();
    for (int k = 0; k < 200; ++k) {
      const RmPose rm{vm.mount().origin + Vec3(1, 2, 3), random_unit(&rng)};
      VmAngles theta = random_theta(vm, &rng);
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      EXPECT_TRUE(res.converged) << c.name;
      VmAngles closed = vm.zero_angles();
      ASSERT_TRUE(vm.aligned(rm, &closed));
      EXPECT_LE((vm.pose(theta).axis - vm.pose(closed).axis).norm(), 1e-9)
          << c.name << " iterations " << res.iterations;
      EXPECT_LE(res.cost, 1e-16) << c.name;  // the link reaches the axis
    }
  }
}

// identity: a blend W = (1,1,1,w,w,w) (w = L^2: a radian weighs like an arc
// of length L) places the VM no worse than either closed form, at a
// stationary point of the cost (J^T W r = 0); on the circle, between the
// nearest and the aligned angles
TEST(PlaceGaussNewton, BlendIsOptimalAndBetweenTheClosedForms) {
  std::mt19937 rng(204);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    PlacementOptions opt;
    opt.weights << 1, 1, 1, L * L, L * L, L * L;
    // random stylus axes make large residuals, where Gauss-Newton contracts
    // only linearly (rates up to ~0.9): this checks the optimum, not speed
    opt.max_iterations = 1000;
    int between_checked = 0, not_converged = 0;
    double worst_optimality = 0;
    for (int k = 0; k < 200; ++k) {
      const RmPose rm{rm_position(vm, &rng), random_unit(&rng)};
      VmAngles near = vm.zero_angles(), aligned = vm.zero_angles();
      ASSERT_TRUE(vm.nearest(rm, &near));
      ASSERT_TRUE(vm.aligned(rm, &aligned));
      VmAngles theta = near;  // the controller's seed
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      if (!res.converged) ++not_converged;
      const double cost = cost_at(vm, rm, opt.weights, theta);
      const double tol = 1e-12 * L * L;
      EXPECT_LE(cost, cost_at(vm, rm, opt.weights, near) + tol) << c.name;
      EXPECT_LE(cost, cost_at(vm, rm, opt.weights, aligned) + tol) << c.name;
      worst_optimality =
          std::max(worst_optimality, optimality(vm, rm, opt.weights, theta));
      if (vm.kind() == VmKind::kCircle) {
        const double span = wrap_angle(aligned[0] - near[0]);
        if (std::abs(span) < kPi - 0.1) {
          const double t = wrap_angle(theta[0] - near[0]);
          EXPECT_GE(t * span, -1e-9) << c.name;  // same side as aligned
          EXPECT_LE(std::abs(t), std::abs(span) + 1e-9) << c.name;
          ++between_checked;
        }
      }
    }
    EXPECT_EQ(not_converged, 0) << c.name;
    EXPECT_LE(worst_optimality, 1e-8) << c.name;
    if (vm.kind() == VmKind::kCircle) {
      EXPECT_GT(between_checked, 150);
    }
  }
}

// An RM that sits near the VM (as under control: 1e-4 L off the path, the
// stylus along the link), the VM placed there, then the RM moved by `move`
// times L and its stylus tilted by `move` rad. Returns the iterations of
// the warm-started placement, or -1 if it did not converge.
int warm_start_iterations(const VirtualMechanism& vm, const Vec6& weights,
                          double move, std::mt19937* rng) {
  const double L = vm.length();
  VmAngles theta = random_theta(vm, rng);
  const VmPose at = vm.pose(theta);
  RmPose rm{at.p + 1e-4 * L * at.axis, at.axis};
  PlacementOptions cold;
  cold.weights = weights;
  cold.max_iterations = 200;
  if (!place_gauss_newton(vm, rm, cold, JointMask{0}, &theta).converged)
    return -2;
  rm.p += move * L * random_unit(rng);
  rm.axis = Eigen::AngleAxisd(move, random_unit(rng)) * rm.axis;
  PlacementOptions opt;  // the controller's 20 iterations
  opt.weights = weights;
  const PlacementResult res =
      place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
  return res.converged ? res.iterations : -1;
}

// identity: from the previous answer, after a small move (1e-4 L, 1e-4 rad)
// of an RM near the path, placement converges in <= 3 iterations (two
// contracting steps and the confirming one)
TEST(PlaceGaussNewton, WarmStartConvergesInFewIterations) {
  std::mt19937 rng(205);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const double L = c.vm->length();
    for (int blend = 0; blend < 2; ++blend) {
      Vec6 w = position_weights();
      if (blend) w.tail<3>().setConstant(L * L);
      int worst = 0;
      for (int k = 0; k < 200; ++k) {
        const int it = warm_start_iterations(*c.vm, w, 1e-4, &rng);
        ASSERT_GT(it, 0) << c.name << " blend " << blend;
        worst = std::max(worst, it);
      }
      EXPECT_LE(worst, 3) << c.name << " blend " << blend;
    }
  }
}

// identity: a larger move (1e-3 L: 50 mm/s at 1 kHz for L = 50 mm) needs
// one more contracting step (the rate |1 - d/L| is ~1e-3): 3 steps and the
// confirming iteration; allow 5. The iteration must not idle once the step
// is down at the cost's rounding level.
TEST(PlaceGaussNewton, WarmStartAfterALargerMoveDoesNotIdle) {
  std::mt19937 rng(209);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const double L = c.vm->length();
    for (int blend = 0; blend < 2; ++blend) {
      Vec6 w = position_weights();
      if (blend) w.tail<3>().setConstant(L * L);
      int worst = 0, over = 0;
      for (int k = 0; k < 500; ++k) {
        const int it = warm_start_iterations(*c.vm, w, 1e-3, &rng);
        ASSERT_GT(it, 0) << c.name << " blend " << blend;
        worst = std::max(worst, it);
        if (it > 5) ++over;
      }
      EXPECT_LE(worst, 5) << c.name << " blend " << blend << ": " << over
                          << " of 500 took more than 5 iterations";
    }
  }
}

// identity: locked joints stay exactly where they were; the surface with its
// contact locked (mask 3) under W_p turns the probe toward the RM, which is
// its nearest() closed form
TEST(PlaceGaussNewton, LockedJointsStayAndSurfaceStickingIsNearest) {
  std::mt19937 rng(206);
  for (const Case& c : cases({VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    for (const Vec6& w : {position_weights(), Vec6(Vec6::Ones())}) {
      PlacementOptions opt;
      opt.weights = w;
      double worst = 0;
      for (int k = 0; k < 100; ++k) {
        const VmAngles start = random_theta(vm, &rng);
        const RmPose rm{static_cast<const SurfaceVm&>(vm).contact(start) +
                            uniform(&rng, 0.5, 1.5) * L * random_unit(&rng),
                        random_unit(&rng)};
        VmAngles theta = start;
        const PlacementResult res =
            place_gauss_newton(vm, rm, opt, JointMask{3}, &theta);
        EXPECT_TRUE(res.converged) << c.name;
        EXPECT_EQ(theta[0], start[0]) << c.name;
        EXPECT_EQ(theta[1], start[1]) << c.name;
        if (w[3] == 0.0) {
          VmAngles closed = start;
          ASSERT_TRUE(vm.nearest(rm, &closed));
          worst = std::max(worst, (vm.pose(theta).p - vm.pose(closed).p).norm());
        }
      }
      EXPECT_LE(worst, std::max(1e-9, 2 * opt.tolerance) * L)
          << c.name << ": worst |X_GN - X_nearest| / L = " << worst / L;
    }
  }
}

// |J^T W r| over |J^T W J|: how far (in joint units) a Gauss-Newton step
// would still go from theta; zero at a stationary point
double gradient_over_curvature(const VirtualMechanism& vm, const RmPose& rm,
                               const Vec6& w, const VmAngles& theta) {
  const MatrixXd J = dynamic_copy([&] {
    VmJacobian Jv;
    vm.jacobian(theta, &Jv);
    return Jv;
  }());
  const VectorXd Wr = w.cwiseProduct(placement_residual(vm, rm, theta));
  const MatrixXd A = J.transpose() * w.asDiagonal() * J;
  return (J.transpose() * Wr).norm() / A.norm();
}

// identity: the surface with W = I (all five joints free): J^T W r = 0 at the
// result, the contact lies on the plane and under the handle along the link,
// and the cost is no larger than at the aligned closed form (stylus axis,
// contact under the tip). The surface's iteration contracts only linearly
// (rates ~0.9 with large residuals, as control_law.h says), so a last step
// below the tolerance can leave ~10 tolerances: J^T W r is checked against
// |J^T W J| times 10 tolerances, and relative to |J| |W r| at 1e-7.
TEST(PlaceGaussNewton, SurfaceIdentityWeightIsOptimalOnThePlane) {
  std::mt19937 rng(207);
  for (const Case& c : cases({VmKind::kSurface})) {
    const auto& vm = static_cast<const SurfaceVm&>(*c.vm);
    const double L = vm.length();
    const Vec3 o = vm.mount().origin, n = vm.normal();
    PlacementOptions opt;
    opt.weights = Vec6::Ones();
    opt.max_iterations = 1000;  // the optimum, not the speed
    int not_converged = 0;
    double worst_optimality = 0, worst_gradient = 0;
    for (int k = 0; k < 100; ++k) {
      const RmPose rm = random_pose_above(vm, &rng);
      VmAngles aligned = random_theta(vm, &rng);
      ASSERT_TRUE(vm.aligned(rm, &aligned));
      VmAngles theta = aligned;
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      if (!res.converged) ++not_converged;
      worst_optimality =
          std::max(worst_optimality, optimality(vm, rm, opt.weights, theta));
      worst_gradient = std::max(
          worst_gradient, gradient_over_curvature(vm, rm, opt.weights, theta));
      const Vec3 contact = vm.contact(theta);
      EXPECT_NEAR((contact - o).dot(n), 0.0, 1e-12 * (1 + L)) << c.name;
      const VmPose pose = vm.pose(theta);
      EXPECT_LE((pose.p - L * pose.axis - contact).norm(), 1e-12 * (1 + L));
      EXPECT_LE(cost_at(vm, rm, opt.weights, theta),
                cost_at(vm, rm, opt.weights, aligned) + 1e-12 * (1 + L * L))
          << c.name;
    }
    EXPECT_EQ(not_converged, 0) << c.name;
    EXPECT_LE(worst_gradient, 10 * opt.tolerance) << c.name;
    EXPECT_LE(worst_optimality, 1e-7) << c.name;
  }
}

// SurfaceVm::placement_minimum (the cost reduced to one angle): the point it
// gives is the placement's optimum to the same optimality as a long
// Gauss-Newton run, its cost is no higher than that run's, and Gauss-Newton
// started there converges without finding a lower cost; with the contact
// free and held, under W = I and another block-isotropic W.
TEST(SurfacePlacementMinimum, IsTheOptimumGaussNewtonConfirms) {
  std::mt19937 rng(1818);
  for (const Case& c : cases({VmKind::kSurface})) {
    const auto& vm = static_cast<const SurfaceVm&>(*c.vm);
    const double L = vm.length();
    for (int held = 0; held < 2; ++held) {
      for (int wk = 0; wk < 2; ++wk) {
        PlacementOptions opt;
        opt.weights = Vec6::Ones();
        if (wk == 1) opt.weights << 0.3, 0.3, 0.3, 4.0, 4.0, 4.0;
        const JointMask locked = held != 0 ? vm.stick_joints() : JointMask{0};
        int found = 0;
        double worst_optimality = 0, worst_gradient = 0;
        for (int k = 0; k < 100; ++k) {
          const RmPose rm = random_pose_above(vm, &rng);
          VmAngles start = random_theta(vm, &rng);
          ASSERT_TRUE(vm.aligned(rm, &start));
          VmAngles theta = start;
          if (!vm.placement_minimum(rm, opt.weights[0], opt.weights[3],
                                    held != 0, &theta)) {
            continue;
          }
          ++found;
          if (held != 0) {
            // the contact stays where it was
            EXPECT_LE((vm.contact(theta) - vm.contact(start)).norm(),
                      1e-12 * (1 + L));
          }
          // a long Gauss-Newton run from the same start
          PlacementOptions slow = opt;
          slow.max_iterations = 2000;
          VmAngles reference = start;
          place_gauss_newton(vm, rm, slow, locked, &reference);
          const double scale = 1e-9 * (1 + L * L);
          EXPECT_LE(cost_at(vm, rm, opt.weights, theta),
                    cost_at(vm, rm, opt.weights, reference) + scale)
              << c.name;
          if (held == 0) {
            worst_optimality = std::max(
                worst_optimality, optimality(vm, rm, opt.weights, theta));
            worst_gradient =
                std::max(worst_gradient,
                         gradient_over_curvature(vm, rm, opt.weights, theta));
          }
          // Gauss-Newton from there converges and finds nothing lower (its
          // steps below 1e-6 are taken on the model's word and may wander
          // along the valley's floor, where the cost cannot tell them apart)
          VmAngles confirmed = theta;
          const PlacementResult res =
              place_gauss_newton(vm, rm, opt, locked, &confirmed);
          EXPECT_TRUE(res.converged) << c.name;
          EXPECT_GE(res.cost, cost_at(vm, rm, opt.weights, theta) - scale)
              << c.name;
        }
        EXPECT_GT(found, 90) << c.name;
        EXPECT_LE(worst_gradient, 10 * opt.tolerance) << c.name;
        EXPECT_LE(worst_optimality, 1e-7) << c.name;
      }
    }
  }
}

}  // namespace
}  // namespace vmh
