// The orientation error of controller/virtual_mechanism, both formulations,
// against routes that do not share its code: the thesis's wrapped angle
// differences typed from eq. 3.32-3.37, Eigen's AngleAxis for the rotation
// carrying the stylus onto the link, central finite differences for its
// derivative, and J_V times small angle steps to first order.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

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

using testing::all_cases;
using testing::Case;
using testing::cases;
using testing::random_theta;
using testing::random_unit;
using testing::uniform;

// identity: the thesis's circle row is wrap(theta_V - theta_R) about the
// plane normal, (-pi, pi]: pi - 0.1 against -pi + 0.1 is -0.2, not 2 pi - 0.2
TEST(VmThesisError, CircleWrapsAcrossPi) {
  for (const Case& c : cases({VmKind::kCircle})) {
    const VirtualMechanism& vm = *c.vm;
    VmAngles tv(1), tr(1);
    tv << kPi - 0.1;
    tr << -kPi + 0.1;
    const Vec3 e = vm.thesis_orientation_error(tv, tr);
    EXPECT_LE((e - (-0.2) * vm.mount().R.col(2)).norm(), 1e-12) << c.name;
    EXPECT_LE((vm.thesis_orientation_error(tr, tv) -
               0.2 * vm.mount().R.col(2)).norm(),
              1e-12)
        << c.name;
  }
  // default mount: the z row, as §3.3.1 has it
  const CircleVm circle(VmMount{}, 50.0);
  VmAngles tv(1), tr(1);
  tv << 0.3;
  tr << -0.2;
  EXPECT_LE((circle.thesis_orientation_error(tv, tr) - Vec3(0, 0, 0.5)).norm(),
            1e-15);
}

// identity: the sphere's thesis rows are (0, d theta2, d theta1) in the
// pivot frame (eq. 3.35-3.37), each difference wrapped
TEST(VmThesisError, SphereRowsWrapped) {
  for (const Case& c : cases({VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const Mat3& R = vm.mount().R;
    VmAngles tv(3), tr(3);
    tv << kPi - 0.1, 0.5, 3.0;
    tr << -kPi + 0.1, 0.3, -3.0;  // twist difference ignored (eq. 3.35)
    const Vec3 e = R.transpose() * vm.thesis_orientation_error(tv, tr);
    EXPECT_LE((e - Vec3(0.0, 0.2, -0.2)).norm(), 1e-12) << c.name;
    tv << 0.4, 0.1, 0.0;
    tr << 0.1, 0.1 + 2 * kPi + 0.05, 1.0;
    EXPECT_LE((R.transpose() * vm.thesis_orientation_error(tv, tr) -
               Vec3(0.0, -0.05, 0.3))
                  .norm(),
              1e-12)
        << c.name;
  }
}

// identity: the geometric error e is the rotation vector that carries the
// stylus axis onto the link axis: AngleAxis(|e|, e/|e|) a = u, |e| is the
// angle between them, e is perpendicular to both; sphere and surface
TEST(VmGeometricError, RotatesTheStylusOntoTheLink) {
  std::mt19937 rng(51);
  for (const Case& c : cases({VmKind::kSphere, VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    for (int k = 0; k < 1000; ++k) {
      const VmPose pose = vm.pose(random_theta(vm, &rng));
      const RmPose rm{Vec3(1, 2, 3), random_unit(&rng)};
      bool ambiguous = true;
      const Vec3 e = vm.geometric_orientation_error(pose, rm, &ambiguous);
      EXPECT_FALSE(ambiguous);
      const Vec3 turned = Eigen::AngleAxisd(e.norm(), e.normalized()) * rm.axis;
      EXPECT_LE((turned - pose.axis).norm(), 1e-12) << c.name;
      EXPECT_NEAR(e.norm(), std::acos(std::clamp(rm.axis.dot(pose.axis), -1.0, 1.0)),
                  1e-7)
          << c.name;
      EXPECT_NEAR(e.dot(rm.axis), 0.0, 1e-12) << c.name;
      EXPECT_NEAR(e.dot(pose.axis), 0.0, 1e-12) << c.name;
    }
  }
}

// identity: aligned axes give zero, opposite axes a rotation by pi about a
// perpendicular axis (flagged ambiguous) that still carries a onto u
TEST(VmGeometricError, AlignedAndOpposite) {
  for (const Case& c : cases({VmKind::kSphere, VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    std::mt19937 rng(52);
    const VmPose pose = vm.pose(random_theta(vm, &rng));
    bool ambiguous = true;
    EXPECT_LE(vm.geometric_orientation_error(pose, RmPose{Vec3(), pose.axis},
                                             &ambiguous)
                  .norm(),
              1e-15);
    EXPECT_FALSE(ambiguous);
    const Vec3 e =
        vm.geometric_orientation_error(pose, RmPose{Vec3(), -pose.axis}, &ambiguous);
    EXPECT_TRUE(ambiguous) << c.name;
    EXPECT_NEAR(e.norm(), kPi, 1e-12);
    EXPECT_LE((Eigen::AngleAxisd(e.norm(), e.normalized()) * (-pose.axis) -
               pose.axis).norm(),
              1e-12)
        << c.name;
  }
}

// identity: the circle's geometric error turns the stylus's normalised
// in-plane projection onto the link, about the plane normal; and it equals
// the thesis error with theta_R from aligned() (§3.3.1)
TEST(VmGeometricError, CircleProjectsAndAgreesWithThesis) {
  std::mt19937 rng(53);
  for (const Case& c : cases({VmKind::kCircle})) {
    const VirtualMechanism& vm = *c.vm;
    const Vec3 n = vm.mount().R.col(2);
    int compared = 0;
    for (int k = 0; k < 1000; ++k) {
      const VmAngles tv = random_theta(vm, &rng);
      const VmPose pose = vm.pose(tv);
      const RmPose rm{Vec3(1, 2, 3), random_unit(&rng)};
      bool ambiguous = true;
      const Vec3 e = vm.geometric_orientation_error(pose, rm, &ambiguous);
      EXPECT_FALSE(ambiguous);
      EXPECT_LE((e - e.dot(n) * n).norm(), 1e-14) << c.name;  // along n
      const Vec3 proj = (rm.axis - rm.axis.dot(n) * n).normalized();
      const Vec3 turned = Eigen::AngleAxisd(e.dot(n), n) * proj;
      EXPECT_LE((turned - pose.axis).norm(), 1e-12) << c.name;
      VmAngles tr = vm.zero_angles();
      ASSERT_TRUE(vm.aligned(rm, &tr));
      // away from the +-pi cut, where either sign is right
      if (std::abs(std::abs(e.dot(n)) - kPi) > 1e-6) {
        EXPECT_LE((vm.thesis_orientation_error(tv, tr) - e).norm(), 1e-12)
            << c.name;
        ++compared;
      }
    }
    EXPECT_GT(compared, 990);
    // the stylus along the normal: no projection, ambiguous
    bool ambiguous = false;
    const Vec3 e = vm.geometric_orientation_error(
        vm.pose(vm.zero_angles()), RmPose{Vec3(), n}, &ambiguous);
    EXPECT_TRUE(ambiguous) << c.name;
    EXPECT_TRUE(e.allFinite());
  }
}

// identity: near alignment the sphere's geometric error agrees to first
// order with J_rot (theta_V - theta_R) minus its component along the link
// (the rotation about the link, which the twist column and part of the
// azimuth column carry, does not move the axis): the difference is O(d^2)
TEST(VmGeometricError, SphereIsJacobianTimesAngleDifferenceToFirstOrder) {
  std::mt19937 rng(54);
  for (const Case& c : cases({VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    for (int k = 0; k < 200; ++k) {
      const VmAngles tv = random_theta(vm, &rng);
      const VmPose pose = vm.pose(tv);
      const Vec3 u = pose.axis;
      VmJacobian J;
      vm.jacobian(tv, &J);
      const VmAngles dir = VmAngles(Vec3(random_unit(&rng)));
      double err[2];
      const double deltas[2] = {1e-3, 1e-4};
      for (int i = 0; i < 2; ++i) {
        const VmAngles tr = tv - deltas[i] * dir;
        const RmPose rm{Vec3(), vm.pose(tr).axis};
        const Vec3 e = vm.geometric_orientation_error(pose, rm, nullptr);
        Vec3 lin = J.bottomRows<3>() * (tv - tr);
        lin -= lin.dot(u) * u;
        err[i] = (e - lin).norm();
        EXPECT_LE(err[i], 20 * deltas[i] * deltas[i]) << c.name;
      }
      // second order: a tenth of the offset, about a hundredth of the error
      EXPECT_LE(err[1], err[0] / 30 + 1e-13) << c.name;
    }
  }
}

// identity: orientation_error_jacobian is the derivative of the geometric
// error under a small rotation dw of the link (u -> exp(dw) u): central
// differences over the three axes, at random axes away from opposite; it
// is I - u u^T where the axes coincide (sphere, surface) and n n^T for the
// circle
TEST(VmGeometricError, OrientationErrorJacobianIsItsDerivative) {
  std::mt19937 rng(56);
  const double h = 1e-6;
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    double worst = 0;
    for (int k = 0; k < 500; ++k) {
      const VmPose pose = vm.pose(random_theta(vm, &rng));
      RmPose rm{Vec3(), random_unit(&rng)};
      if (rm.axis.dot(pose.axis) < -0.9) continue;  // near opposite
      const Mat3 M = vm.orientation_error_jacobian(pose, rm);
      for (int j = 0; j < 3; ++j) {
        VmPose plus = pose, minus = pose;
        plus.axis = Eigen::AngleAxisd(h, Vec3::Unit(j)) * pose.axis;
        minus.axis = Eigen::AngleAxisd(-h, Vec3::Unit(j)) * pose.axis;
        const Vec3 d = (vm.geometric_orientation_error(plus, rm, nullptr) -
                        vm.geometric_orientation_error(minus, rm, nullptr)) /
                       (2 * h);
        worst = std::max(worst, (M.col(j) - d).cwiseAbs().maxCoeff());
      }
    }
    EXPECT_LE(worst, 1e-6) << c.name;
    const VmPose pose = vm.pose(random_theta(vm, &rng));
    const Mat3 M0 = vm.orientation_error_jacobian(pose, RmPose{Vec3(), pose.axis});
    const Vec3 n = vm.mount().R.col(2);
    const bool planar =
        vm.kind() == VmKind::kCircle || vm.kind() == VmKind::kLine;
    const Mat3 expected = planar
                              ? Mat3(n * n.transpose())
                              : Mat3(Mat3::Identity() - pose.axis * pose.axis.transpose());
    EXPECT_LE((M0 - expected).norm(), 1e-12) << c.name;
  }
}

// Erratum 26 shown again with the two error functions: at theta1 = 0 the
// polar joint turns the link about (sin t1, -cos t1, 0) = -y. A pure polar
// misalignment theta_V2 - theta_R2 = d gives the thesis's y row +d, but the
// rotation carrying the stylus onto the link is -d about y.
TEST(VmGeometricError, SphereDiffersFromThesisRowsAtTheta1Zero) {
  const SphereVm vm(VmMount{}, 50.0);
  const double d = 1e-3;
  VmAngles tv(3), tr(3);
  tv << 0.0, 1.1, 0.0;
  tr << 0.0, 1.1 - d, 0.0;
  const Vec3 thesis = vm.thesis_orientation_error(tv, tr);
  const Vec3 geometric = vm.geometric_orientation_error(
      vm.pose(tv), RmPose{Vec3(), vm.pose(tr).axis}, nullptr);
  EXPECT_NEAR(thesis.y(), d, 1e-15);
  EXPECT_NEAR(thesis.x(), 0.0, 1e-15);
  EXPECT_NEAR(thesis.z(), 0.0, 1e-15);
  EXPECT_NEAR(geometric.y(), -d, 1e-12);
  EXPECT_NEAR(geometric.x(), 0.0, 1e-12);
  EXPECT_NEAR(geometric.z(), 0.0, 1e-12);
  // an independent truth: Eigen's smallest rotation between the two axes
  const Eigen::AngleAxisd truth(Eigen::Quaterniond::FromTwoVectors(
      vm.pose(tr).axis, vm.pose(tv).axis));
  EXPECT_LE((truth.angle() * truth.axis() - geometric).norm(), 1e-12);
  // the polar column of J_V at theta1 = 0 is -y
  VmJacobian J;
  vm.jacobian(tv, &J);
  EXPECT_LE((J.block<3, 1>(3, 1) - Vec3(0, -1, 0)).norm(), 1e-15);
}

// identity: the surface's thesis-style error wraps each revolute difference
// and, near alignment (no twist difference), agrees with the geometric
// error up to the part along the link (alpha's joint axis has one)
TEST(VmThesisError, SurfaceWrapsAndMatchesGeometricToFirstOrder) {
  std::mt19937 rng(55);
  for (const Case& c : cases({VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    for (int k = 0; k < 200; ++k) {
      const VmAngles tv = random_theta(vm, &rng);
      const double d = 1e-4;
      VmAngles tr = tv;
      tr[2] -= d * uniform(&rng, -1, 1);
      tr[3] -= d * uniform(&rng, -1, 1);
      const Vec3 u = vm.pose(tv).axis;
      Vec3 e = vm.thesis_orientation_error(tv, tr);
      e -= e.dot(u) * u;
      const Vec3 g = vm.geometric_orientation_error(
          vm.pose(tv), RmPose{Vec3(), vm.pose(tr).axis}, nullptr);
      EXPECT_LE((e - g).norm(), 20 * d * d) << c.name;
      // 2 pi added to any revolute difference changes nothing
      VmAngles tr2 = tr;
      tr2[2] += 2 * kPi;
      tr2[3] -= 2 * kPi;
      tr2[4] += 4 * kPi;
      EXPECT_LE((vm.thesis_orientation_error(tv, tr2) -
                 vm.thesis_orientation_error(tv, tr)).norm(),
                1e-12)
          << c.name;
    }
  }
}

// ------------------------------------------------------- names, construction

}  // namespace
}  // namespace vmh
