// Checks of controller/virtual_mechanism against routes that do not share its
// code: central finite differences of the handle pose, the thesis's closed
// forms typed here from chapter 3 (eq. 3.25-3.31, §3.3.1, §3.4.1), brute-force
// searches of the VM's path, and geometric identities (rotation matrices,
// distances, Eigen's AngleAxis).
//
// Every VM is checked with the default mount and with a pivot away from the
// origin in a turned frame, at a long (50) and a short (0.05) link.
#include "controller/virtual_mechanism.h"
#include "controller/vm_circle.h"
#include "controller/vm_line.h"
#include "controller/vm_registry.h"
#include "controller/vm_sphere.h"
#include "controller/vm_surface.h"
#include "tests/support/random_vm.h"
#include "tests/support/vm_cases.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;

// ------------------------------------------------------------------ helpers

using testing::all_cases;
using testing::Case;
using testing::cases;
using testing::turned_mount;
using testing::random_theta;
using testing::random_unit;
using testing::uniform;


// vee of the skew part of a (nearly) skew matrix
Vec3 vee(const Mat3& S) {
  const Mat3 A = 0.5 * (S - S.transpose());
  return Vec3(A(2, 1), A(0, 2), A(1, 0));
}

// the column of the handle frame that the header documents as the link axis
Vec3 documented_axis_column(const VirtualMechanism& vm, const Mat3& R) {
  const bool planar =
      vm.kind() == VmKind::kCircle || vm.kind() == VmKind::kLine;
  return planar ? Vec3(R.col(0)) : Vec3(R.col(2));
}

// where the link starts: the pivot, or the surface's contact point
Vec3 link_base(const VirtualMechanism& vm, const VmAngles& theta) {
  if (vm.kind() == VmKind::kSurface) {
    // c = o + s1 t1 + s2 t2 (header), written out here
    return vm.mount().origin + theta[0] * vm.mount().R.col(0) +
           theta[1] * vm.mount().R.col(1);
  }
  return vm.mount().origin;
}

// -------------------------------------------------- Jacobian vs differences

// identity: J_V(theta) rows 0-2 = (p(theta + h e_j) - p(theta - h e_j)) / 2h
// and rows 3-5 = vee((R(theta + h e_j) - R(theta - h e_j)) / 2h R^T), for
// 500 random theta per VM, mount and length
TEST(VmJacobian, EqualsCentralFiniteDifferences) {
  std::mt19937 rng(11);
  const double h = 1e-6;
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    double worst_lin = 0, worst_rot = 0, worst_skew = 0;
    for (int k = 0; k < 500; ++k) {
      const VmAngles theta = random_theta(vm, &rng);
      VmJacobian J;
      vm.jacobian(theta, &J);
      ASSERT_EQ(J.rows(), 6);
      ASSERT_EQ(J.cols(), vm.dof()) << c.name;
      const Mat3 R = vm.pose(theta).R;
      for (int j = 0; j < vm.dof(); ++j) {
        VmAngles tp = theta, tm = theta;
        tp[j] += h;
        tm[j] -= h;
        const VmPose a = vm.pose(tp), b = vm.pose(tm);
        const Vec3 v = (a.p - b.p) / (2 * h);
        const Mat3 dR = (a.R - b.R) / (2 * h);
        const Mat3 S = dR * R.transpose();  // skew for a rotation
        // a revolute column is in length units, a prismatic one is unitless
        const double scale = vm.is_revolute(j) ? L : 1.0;
        worst_lin = std::max(
            worst_lin, (J.block<3, 1>(0, j) - v).cwiseAbs().maxCoeff() / scale);
        worst_rot = std::max(worst_rot,
                             (J.block<3, 1>(3, j) - vee(S)).cwiseAbs().maxCoeff());
        worst_skew = std::max(worst_skew,
                              (S + S.transpose()).cwiseAbs().maxCoeff());
      }
    }
    EXPECT_LE(worst_lin, 1e-6) << c.name;
    EXPECT_LE(worst_rot, 1e-6) << c.name;
    EXPECT_LE(worst_skew, 1e-6) << c.name;  // sanity of the difference
  }
}

// ------------------------------------------------------------ pose geometry

// identity: R is a rotation, the axis is unit and is R's documented column
// (circle x, sphere and surface z), the handle lies L from the pivot /
// contact along the axis, the surface's contact lies on its plane, and the
// circle's handle in its plane
TEST(VmPose, FrameAxisAndLinkLength) {
  std::mt19937 rng(12);
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 n = vm.mount().R.col(2);
    for (int k = 0; k < 500; ++k) {
      const VmAngles theta = random_theta(vm, &rng);
      const VmPose pose = vm.pose(theta);
      EXPECT_LE((pose.R.transpose() * pose.R - Mat3::Identity()).norm(), 1e-12)
          << c.name;
      EXPECT_NEAR(pose.R.determinant(), 1.0, 1e-12) << c.name;
      EXPECT_NEAR(pose.axis.norm(), 1.0, 1e-12) << c.name;
      EXPECT_LE((pose.axis - documented_axis_column(vm, pose.R)).norm(), 1e-12)
          << c.name;
      if (vm.kind() == VmKind::kLine) {
        // on the line through the origin along the pivot frame's y, the
        // handle frame the pivot frame (the link never turns)
        const Vec3 t = vm.mount().R.col(1), d = pose.p - vm.mount().origin;
        EXPECT_LE((d - d.dot(t) * t).norm(), 1e-12 * (1 + L)) << c.name;
        EXPECT_NEAR(d.dot(t), theta[0], 1e-12 * (1 + L)) << c.name;
        EXPECT_LE((pose.R - vm.mount().R).norm(), 0.0) << c.name;
        continue;
      }
      const Vec3 base = link_base(vm, theta);
      EXPECT_NEAR((pose.p - base).norm(), L, 1e-12 * (1 + L)) << c.name;
      EXPECT_LE((pose.p - base - L * pose.axis).norm(), 1e-12 * (1 + L))
          << c.name;
      if (vm.kind() == VmKind::kCircle) {
        EXPECT_NEAR((pose.p - vm.mount().origin).dot(n), 0.0, 1e-12 * (1 + L))
            << c.name;
      }
      if (vm.kind() == VmKind::kSurface) {
        const auto& s = static_cast<const SurfaceVm&>(vm);
        EXPECT_NEAR((s.contact(theta) - vm.mount().origin).dot(n), 0.0,
                    1e-12 * (1 + L))
            << c.name;
        EXPECT_LE((s.contact(theta) - base).norm(), 1e-12 * (1 + L)) << c.name;
        EXPECT_LE((s.normal() - n).norm(), 0.0) << c.name;
      }
    }
  }
}

// identity: eq. 3.25/3.26 (circle) and eq. 3.29/3.30 (sphere) as typed from
// the thesis, for a pivot frame aligned with the device frame (the thesis's
// setting) at the origin and at (X0, Y0, Z0) = (10, -20, 5)
TEST(VmPose, ThesisForwardKinematicsDefaultMount) {
  std::mt19937 rng(13);
  for (const Vec3& o : {Vec3(0, 0, 0), Vec3(10, -20, 5)}) {
    VmMount mount;
    mount.origin = o;
    for (double L : {50.0, 0.05}) {
      const CircleVm circle(mount, L);
      const SphereVm sphere(mount, L);
      for (int k = 0; k < 200; ++k) {
        const double t = uniform(&rng, -kPi, kPi);
        VmAngles tc(1);
        tc << t;
        const VmPose pc = circle.pose(tc);
        // eq. 3.26
        const Vec3 xv(o.x() + L * std::cos(t), o.y() + L * std::sin(t), o.z());
        EXPECT_LE((pc.p - xv).norm(), 1e-12 * (1 + L));
        // eq. 3.25's rotation
        Mat3 R25;
        R25 << std::cos(t), -std::sin(t), 0, std::sin(t), std::cos(t), 0, 0, 0,
            1;
        EXPECT_LE((pc.R - R25).norm(), 1e-14);

        const double t1 = uniform(&rng, -kPi, kPi);
        const double t2 = uniform(&rng, 0.0, kPi);
        const double t3 = uniform(&rng, -kPi, kPi);
        VmAngles ts(3);
        ts << t1, t2, t3;
        const VmPose ps = sphere.pose(ts);
        const double c1 = std::cos(t1), s1 = std::sin(t1);
        const double c2 = std::cos(t2), s2 = std::sin(t2);
        const double c3 = std::cos(t3), s3 = std::sin(t3);
        // eq. 3.30
        const Vec3 xs(o.x() + L * c1 * s2, o.y() + L * s1 * s2, o.z() - L * c2);
        EXPECT_LE((ps.p - xs).norm(), 1e-12 * (1 + L));
        // eq. 3.29's r11..r33
        Mat3 R29;
        R29(0, 0) = s1 * s3 + c1 * c2 * c3;
        R29(1, 0) = s1 * c2 * c3 - c1 * s3;
        R29(2, 0) = s2 * c3;
        R29(0, 1) = s1 * c3 - c1 * c2 * s3;
        R29(1, 1) = -c1 * c3 - s1 * c2 * s3;
        R29(2, 1) = -s2 * s3;
        R29(0, 2) = c1 * s2;
        R29(1, 2) = s1 * s2;
        R29(2, 2) = -c2;
        EXPECT_LE((ps.R - R29).norm(), 1e-14);
      }
    }
  }
}

// identity: with a turned mount the thesis's forms hold in the pivot frame:
// circle X = o + L R (c, s, 0), sphere X = o + L R (c1 s2, s1 s2, -c2);
// the surface's direction is u = cos b t1 + sin b (cos a t2 + sin a n)
TEST(VmPose, TurnedMountIsThePivotFrameForm) {
  std::mt19937 rng(14);
  const VmMount m = turned_mount();
  const Vec3 t1 = m.R.col(0), t2 = m.R.col(1), n = m.R.col(2);
  for (double L : {50.0, 0.05}) {
    const CircleVm circle(m, L);
    const SphereVm sphere(m, L);
    const SurfaceVm surface(m, L);
    for (int k = 0; k < 200; ++k) {
      VmAngles tc = random_theta(circle, &rng);
      EXPECT_LE((circle.pose(tc).p -
                 (m.origin + L * (std::cos(tc[0]) * t1 + std::sin(tc[0]) * t2)))
                    .norm(),
                1e-12 * (1 + L));
      VmAngles ts = random_theta(sphere, &rng);
      const Vec3 local(std::cos(ts[0]) * std::sin(ts[1]),
                       std::sin(ts[0]) * std::sin(ts[1]), -std::cos(ts[1]));
      EXPECT_LE((sphere.pose(ts).p - (m.origin + L * m.R * local)).norm(),
                1e-12 * (1 + L));
      VmAngles tf = random_theta(surface, &rng);
      const double a = tf[2], b = tf[3];
      const Vec3 u = std::cos(b) * t1 +
                     std::sin(b) * (std::cos(a) * t2 + std::sin(a) * n);
      const Vec3 c = m.origin + tf[0] * t1 + tf[1] * t2;
      EXPECT_LE((surface.pose(tf).axis - u).norm(), 1e-12);
      EXPECT_LE((surface.pose(tf).p - (c + L * u)).norm(), 1e-12 * (1 + L));
    }
  }
  // the surface's upright probe (u = n) is at alpha = beta = pi/2
  const SurfaceVm surface(m, 1.0);
  VmAngles up(5);
  up << 0.3, -0.2, kPi / 2, kPi / 2, 0.4;
  EXPECT_LE((surface.pose(up).axis - n).norm(), 1e-15);
}

// identity: J_V equals eq. 3.27 (circle) and eq. 3.31 (sphere) as typed from
// the thesis, default mount
TEST(VmJacobian, ThesisClosedFormsDefaultMount) {
  std::mt19937 rng(15);
  for (double L : {50.0, 0.05}) {
    const CircleVm circle(VmMount{}, L);
    const SphereVm sphere(VmMount{}, L);
    for (int k = 0; k < 200; ++k) {
      const double t = uniform(&rng, -kPi, kPi);
      VmAngles tc(1);
      tc << t;
      VmJacobian Jc;
      circle.jacobian(tc, &Jc);
      Eigen::Matrix<double, 6, 1> J27;
      J27 << -L * std::sin(t), L * std::cos(t), 0, 0, 0, 1;
      EXPECT_LE((Jc - J27).cwiseAbs().maxCoeff(), 1e-14 * (1 + L));

      const double t1 = uniform(&rng, -kPi, kPi);
      const double t2 = uniform(&rng, 0.0, kPi);
      VmAngles ts(3);
      ts << t1, t2, uniform(&rng, -kPi, kPi);
      VmJacobian Js;
      sphere.jacobian(ts, &Js);
      const double c1 = std::cos(t1), s1 = std::sin(t1);
      const double c2 = std::cos(t2), s2 = std::sin(t2);
      Eigen::Matrix<double, 6, 3> J31;
      J31 << -L * s1 * s2, L * c1 * c2, 0,  //
          L * c1 * s2, L * s1 * c2, 0,      //
          0, L * s2, 0,                     //
          0, s1, c1 * s2,                   //
          0, -c1, s1 * s2,                  //
          1, 0, -c2;
      EXPECT_LE((Js - J31).cwiseAbs().maxCoeff(), 1e-14 * (1 + L));
    }
  }
}

// ------------------------------------------------------------------ nearest

// the distance from p to the nearest of the points (x, y, z in a row), in
// plain doubles: the test code is compiled without optimisation, where an
// Eigen expression per point cost about ten times as much. The square root
// of the least square is the least of the roots (both correctly rounded).
double vmt_min_distance(const std::vector<double>& xyz, const Vec3& p) {
  double best2 = std::numeric_limits<double>::infinity();
  const double px = p.x(), py = p.y(), pz = p.z();
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
    const double dx = xyz[i] - px, dy = xyz[i + 1] - py, dz = xyz[i + 2] - pz;
    best2 = std::min(best2, dx * dx + dy * dy + dz * dz);
  }
  return std::sqrt(best2);
}

void vmt_push(std::vector<double>* xyz, const Vec3& x) {
  xyz->push_back(x.x());
  xyz->push_back(x.y());
  xyz->push_back(x.z());
}

// identity: the circle's nearest() puts the handle at the closest of 100,000
// sampled points of the circle (none is closer by more than rounding), and
// the best sample is within the sampling resolution of it
TEST(VmNearest, CircleIsClosestByBruteForce) {
  std::mt19937 rng(21);
  const int kSamples = 100000;
  for (const Case& c : cases({VmKind::kCircle})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 o = vm.mount().origin;
    const Vec3 e1 = vm.mount().R.col(0), e2 = vm.mount().R.col(1);
    std::vector<double> path;
    path.reserve(3 * kSamples);
    for (int i = 0; i < kSamples; ++i) {
      const double a = 2 * kPi * i / kSamples;
      vmt_push(&path, o + L * (std::cos(a) * e1 + std::sin(a) * e2));
    }
    for (int k = 0; k < 20; ++k) {
      RmPose rm;
      rm.p = o + uniform(&rng, 0.1, 3.0) * L * random_unit(&rng);
      VmAngles theta = vm.zero_angles();
      ASSERT_TRUE(vm.nearest(rm, &theta)) << c.name;
      const double d = (vm.pose(theta).p - rm.p).norm();
      const double best = vmt_min_distance(path, rm.p);
      EXPECT_GE(best, d - 1e-12 * (1 + L)) << c.name;
      EXPECT_LE(best, d + 1e-3 * L) << c.name;
    }
  }
}

// identity: the sphere's nearest() beats 200,000 random points of the sphere
// (uniform directions from normalised Gaussians, not the VM's angles)
TEST(VmNearest, SphereIsClosestByBruteForce) {
  std::mt19937 rng(22);
  const int kSamples = 200000;
  for (const Case& c : cases({VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 o = vm.mount().origin;
    std::vector<double> path;
    path.reserve(3 * kSamples);
    for (int i = 0; i < kSamples; ++i) vmt_push(&path, o + L * random_unit(&rng));
    for (int k = 0; k < 10; ++k) {
      RmPose rm;
      rm.p = o + uniform(&rng, 0.1, 3.0) * L * random_unit(&rng);
      VmAngles theta = vm.zero_angles();
      ASSERT_TRUE(vm.nearest(rm, &theta)) << c.name;
      const double d = (vm.pose(theta).p - rm.p).norm();
      const double best = vmt_min_distance(path, rm.p);
      EXPECT_GE(best, d - 1e-12 * (1 + L)) << c.name;
      EXPECT_LE(best, d + 2e-2 * L) << c.name;
      // and it is the radial point, o + L (p - o)/|p - o|
      EXPECT_LE((vm.pose(theta).p - (o + L * (rm.p - o).normalized())).norm(),
                1e-12 * (1 + L))
          << c.name;
    }
  }
}

// identity: the surface's nearest() keeps the contact point (s1, s2 and the
// twist untouched) and puts the handle at the closest point of the sphere of
// radius L about it (checked against 50,000 random points of that sphere)
TEST(VmNearest, SurfaceTurnsTheProbeTowardTheRm) {
  std::mt19937 rng(23);
  std::vector<Vec3> directions(50000);
  for (Vec3& u : directions) u = random_unit(&rng);
  for (const Case& c : cases({VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    // the sphere of radius L about the origin, moved to each contact below
    std::vector<double> sphere;
    sphere.reserve(3 * directions.size());
    for (const Vec3& u : directions) vmt_push(&sphere, L * u);
    for (int k = 0; k < 10; ++k) {
      const VmAngles start = random_theta(vm, &rng);
      const Vec3 contact = link_base(vm, start);
      RmPose rm;
      rm.p = contact + uniform(&rng, 0.1, 3.0) * L * random_unit(&rng);
      VmAngles theta = start;
      ASSERT_TRUE(vm.nearest(rm, &theta)) << c.name;
      EXPECT_EQ(theta[0], start[0]);
      EXPECT_EQ(theta[1], start[1]);
      EXPECT_EQ(theta[4], start[4]);
      const double d = (vm.pose(theta).p - rm.p).norm();
      const double best = vmt_min_distance(sphere, rm.p - contact);
      EXPECT_GE(best, d - 1e-12 * (1 + L)) << c.name;
      EXPECT_LE(best, d + 5e-2 * L) << c.name;
    }
  }
}

// identity: §3.3.1 theta_V = atan2(Y - Y0, X - X0) and §3.4.1
// theta_V1 = atan2(Y - Y0, X - X0), theta_V2 = pi - acos((Z - Z0) / LL), for a
// pivot frame aligned with the device frame
TEST(VmNearest, ThesisAnglesDefaultMount) {
  std::mt19937 rng(24);
  for (const Vec3& o : {Vec3(0, 0, 0), Vec3(10, -20, 5)}) {
    VmMount mount;
    mount.origin = o;
    const CircleVm circle(mount, 50.0);
    const SphereVm sphere(mount, 50.0);
    for (int k = 0; k < 1000; ++k) {
      const Vec3 p = o + uniform(&rng, 1.0, 150.0) * random_unit(&rng);
      const RmPose rm{p, Vec3::UnitZ()};
      VmAngles tc = circle.zero_angles();
      ASSERT_TRUE(circle.nearest(rm, &tc));
      EXPECT_NEAR(tc[0], std::atan2(p.y() - o.y(), p.x() - o.x()), 1e-14);
      VmAngles ts = sphere.zero_angles();
      ASSERT_TRUE(sphere.nearest(rm, &ts));
      const double LL = (p - o).norm();
      EXPECT_NEAR(ts[0], std::atan2(p.y() - o.y(), p.x() - o.x()), 1e-14);
      EXPECT_NEAR(ts[1], kPi - std::acos((p.z() - o.z()) / LL), 1e-12);
      EXPECT_EQ(ts[2], 0.0);  // the twist is not the closed form's to set
    }
  }
}

// identity: nearest() returns false and leaves theta untouched with the RM
// at the pivot (circle: also anywhere on the circle's axis; surface: at the
// contact point)
TEST(VmNearest, UndefinedAtThePivot) {
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    std::mt19937 rng(25);
    const VmAngles start = random_theta(vm, &rng);
    VmAngles theta = start;
    const RmPose rm{link_base(vm, start), random_unit(&rng)};
    if (vm.kind() == VmKind::kLine) {
      // a line has no pivot: every point has a foot on it
      EXPECT_TRUE(vm.nearest(rm, &theta)) << c.name;
      EXPECT_LE((vm.position(theta) - vm.nearest_on_path(rm.p)).norm(),
                1e-12 * (1 + vm.length()))
          << c.name;
      continue;
    }
    EXPECT_FALSE(vm.nearest(rm, &theta)) << c.name;
    EXPECT_TRUE(theta == start) << c.name;
    if (vm.kind() == VmKind::kCircle) {
      const RmPose on_axis{
          vm.mount().origin + 2.0 * vm.length() * vm.mount().R.col(2),
          Vec3::UnitZ()};
      EXPECT_FALSE(vm.nearest(on_axis, &theta)) << c.name;
      EXPECT_TRUE(theta == start) << c.name;
    }
  }
}

// identity: on the sphere's pole axis nearest() is defined: theta2 = pi with
// the RM along the pivot frame's +z, 0 along -z; theta1 keeps its value and
// the handle is at o +- L z
TEST(VmNearest, SpherePolesAreFinite) {
  for (const Case& c : cases({VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 o = vm.mount().origin, z = vm.mount().R.col(2);
    for (double sign : {1.0, -1.0}) {
      VmAngles theta(3);
      theta << 0.8, 1.0, -0.3;
      const RmPose rm{o + sign * 2.5 * L * z, Vec3::UnitZ()};
      ASSERT_TRUE(vm.nearest(rm, &theta)) << c.name;
      EXPECT_TRUE(theta.allFinite()) << c.name;
      EXPECT_NEAR(theta[1], sign > 0 ? kPi : 0.0, 1e-7) << c.name;
      EXPECT_EQ(theta[0], 0.8) << c.name;
      EXPECT_LE((vm.pose(theta).p - (o + sign * L * z)).norm(), 1e-7 * L)
          << c.name;
    }
  }
}

// the closed-form tick's combined calls (nearest_pose_jacobian,
// aligned_position) against the calls they combine: the circle and the
// sphere take the pose's sines and cosines from the measured direction
// instead of from the angles, so the two routes differ only by rounding;
// the angles and the verdicts are the same. Random RMs, on-pole RMs and RMs
// at the pivot (where both return false and keep theta).
TEST(VmNearest, CombinedCallsMatchTheCallsTheyCombine) {
  std::mt19937 rng(180);
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 o = vm.mount().origin, z = vm.mount().R.col(2);
    for (int k = 0; k < 600; ++k) {
      const VmAngles start = random_theta(vm, &rng);
      RmPose rm;
      rm.axis = random_unit(&rng);
      rm.p = o + uniform(&rng, 0.1, 3.0) * L * random_unit(&rng);
      if (k % 100 == 1) rm.p = o + 2.0 * L * z;  // the sphere's pole
      if (k % 100 == 2) rm.axis = z;             // stylus on the pole axis
      if (k % 100 == 3) rm.p = link_base(vm, start);  // at the pivot
      if (k % 100 == 4) rm.axis = Vec3::Zero();
      VmAngles parts = start, combined = start;
      VmPose pose_parts, pose_combined;
      VmJacobian J_parts, J_combined;
      const bool ok_parts = vm.nearest(rm, &parts);
      const bool ok_combined =
          vm.nearest_pose_jacobian(rm, &combined, &pose_combined, &J_combined);
      ASSERT_EQ(ok_parts, ok_combined) << c.name << " k = " << k;
      EXPECT_TRUE(parts == combined) << c.name << " k = " << k;
      if (ok_parts) {
        vm.pose_jacobian(parts, &pose_parts, &J_parts);
        EXPECT_LE((pose_combined.p - pose_parts.p).norm(), 1e-12 * (1 + L))
            << c.name << " k = " << k;
        EXPECT_LE((pose_combined.R - pose_parts.R).norm(), 1e-12)
            << c.name << " k = " << k;
        EXPECT_LE((pose_combined.axis - pose_parts.axis).norm(), 1e-12)
            << c.name << " k = " << k;
        ASSERT_EQ(J_combined.cols(), J_parts.cols()) << c.name;
        EXPECT_LE((J_combined - J_parts).norm(), 1e-12 * (1 + L))
            << c.name << " k = " << k;
      }
      VmAngles a_parts = start, a_combined = start;
      Vec3 x_combined;
      const bool aligned_parts = vm.aligned(rm, &a_parts);
      const bool aligned_combined =
          vm.aligned_position(rm, &a_combined, &x_combined);
      ASSERT_EQ(aligned_parts, aligned_combined) << c.name << " k = " << k;
      EXPECT_TRUE(a_parts == a_combined) << c.name << " k = " << k;
      EXPECT_LE((x_combined - vm.position(a_parts)).norm(), 1e-12 * (1 + L))
          << c.name << " k = " << k;
    }
  }
}

// ------------------------------------------------------------------ aligned

// identity: aligned() turns the link onto the stylus axis (sphere, surface)
// or onto its in-plane projection, normalised (circle); the twist is kept;
// the surface's contact goes under the stylus tip p - L a, projected onto
// the plane
TEST(VmAligned, LinkAxisIsTheStylusAxis) {
  std::mt19937 rng(31);
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 n = vm.mount().R.col(2);
    for (int k = 0; k < 500; ++k) {
      const VmAngles start = random_theta(vm, &rng);
      RmPose rm;
      rm.p = vm.mount().origin + 2.0 * L * random_unit(&rng);
      rm.axis = random_unit(&rng);
      VmAngles theta = start;
      ASSERT_TRUE(vm.aligned(rm, &theta)) << c.name;
      const VmPose pose = vm.pose(theta);
      if (vm.kind() == VmKind::kLine) {
        // no s turns the link: theta_R is the foot of the perpendicular
        EXPECT_LE((pose.p - vm.nearest_on_path(rm.p)).norm(), 1e-12 * (1 + L))
            << c.name;
        EXPECT_LE((pose.axis - vm.mount().R.col(0)).norm(), 0.0) << c.name;
        continue;
      }
      if (vm.kind() == VmKind::kCircle) {
        const Vec3 proj = (rm.axis - rm.axis.dot(n) * n).normalized();
        EXPECT_LE((pose.axis - proj).norm(), 1e-12) << c.name;
      } else {
        EXPECT_LE((pose.axis - rm.axis).norm(), 1e-12) << c.name;
      }
      if (vm.kind() == VmKind::kSphere) {
        EXPECT_EQ(theta[2], start[2]);
      }
      if (vm.kind() == VmKind::kSurface) {
        EXPECT_EQ(theta[4], start[4]);
        const Vec3 tip = rm.p - L * rm.axis;
        const Vec3 below = tip - (tip - vm.mount().origin).dot(n) * n;
        EXPECT_LE((link_base(vm, theta) - below).norm(), 1e-12 * (1 + L))
            << c.name;
      }
    }
  }
}

// identity: §3.3.1 theta_R = atan2(Z_y, Z_x) and §3.4.1 theta_R2 =
// pi - acos(Z_z) for the default mount
TEST(VmAligned, ThesisAnglesDefaultMount) {
  std::mt19937 rng(32);
  const CircleVm circle(VmMount{}, 50.0);
  const SphereVm sphere(VmMount{}, 50.0);
  for (int k = 0; k < 1000; ++k) {
    const Vec3 z = random_unit(&rng);
    const RmPose rm{Vec3(1, 2, 3), z};
    VmAngles tc = circle.zero_angles(), ts = sphere.zero_angles();
    ASSERT_TRUE(circle.aligned(rm, &tc));
    ASSERT_TRUE(sphere.aligned(rm, &ts));
    EXPECT_NEAR(tc[0], std::atan2(z.y(), z.x()), 1e-14);
    EXPECT_NEAR(ts[0], std::atan2(z.y(), z.x()), 1e-14);
    EXPECT_NEAR(ts[1], kPi - std::acos(z.z()), 1e-12);
  }
}

// identity: a stylus along the circle's plane normal has no in-plane
// direction: aligned() returns false and leaves theta alone
TEST(VmAligned, CircleUndefinedAlongTheNormal) {
  for (const Case& c : cases({VmKind::kCircle})) {
    const VirtualMechanism& vm = *c.vm;
    for (double sign : {1.0, -1.0}) {
      VmAngles theta(1);
      theta << 0.4;
      const RmPose rm{vm.mount().origin + Vec3(1, 1, 1),
                      sign * vm.mount().R.col(2)};
      EXPECT_FALSE(vm.aligned(rm, &theta)) << c.name;
      EXPECT_EQ(theta[0], 0.4);
    }
  }
}

// ---------------------------------------------------------------- normalize

// identity: normalize() leaves the handle where it was (position, axis and
// the full frame) and brings the angles into their canonical ranges; angles
// far outside (+-7, +-20 rad, negative polar angles) included
TEST(VmNormalize, KeepsTheHandleAndWrapsTheAngles) {
  std::mt19937 rng(41);
  const double wild[] = {-20.0, -7.0, -kPi, -1.0, 0.0, 2.0, kPi, 7.0, 20.0};
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    for (int k = 0; k < 2000; ++k) {
      VmAngles theta = random_theta(vm, &rng);
      for (int j = 0; j < vm.dof(); ++j) {
        if (!vm.is_revolute(j)) continue;
        const int pick = std::uniform_int_distribution<int>(0, 11)(rng);
        if (pick < 9) {
          theta[j] = wild[pick];
        } else {
          theta[j] += 2 * kPi * std::uniform_int_distribution<int>(-4, 4)(rng);
        }
        if (std::uniform_int_distribution<int>(0, 3)(rng) == 0) {
          theta[j] = -theta[j];  // e.g. negative polar angles
        }
      }
      VmAngles t = theta;
      vm.normalize(&t);
      const VmPose before = vm.pose(theta), after = vm.pose(t);
      EXPECT_LE((after.p - before.p).norm(), 1e-9 * (1 + L))
          << c.name << " theta " << theta.transpose();
      EXPECT_LE((after.axis - before.axis).norm(), 1e-9) << c.name;
      EXPECT_LE((after.R - before.R).norm(), 1e-9)
          << c.name << " theta " << theta.transpose();
      for (int j = 0; j < vm.dof(); ++j) {
        if (!vm.is_revolute(j)) {
          EXPECT_EQ(t[j], theta[j]) << c.name;  // prismatic: untouched
          continue;
        }
        const bool polar = (vm.kind() == VmKind::kSphere && j == 1) ||
                           (vm.kind() == VmKind::kSurface && j == 3);
        if (polar) {
          EXPECT_GE(t[j], 0.0) << c.name;
          EXPECT_LE(t[j], kPi) << c.name;
        } else {
          EXPECT_GT(t[j], -kPi) << c.name;
          EXPECT_LE(t[j], kPi) << c.name;
        }
      }
    }
  }
}

// identity: -pi is outside (-pi, pi] and becomes +pi
TEST(VmNormalize, MinusPiBecomesPi) {
  const CircleVm circle(VmMount{}, 1.0);
  VmAngles t(1);
  t << -kPi;
  circle.normalize(&t);
  EXPECT_EQ(t[0], kPi);
}

// -------------------------------------------------------- orientation errors

TEST(VmKindName, RoundTripAndRejection) {
  for (const VmDescriptor& d : vm_registry()) {
    const VmKind k = d.kind;
    VmKind parsed = k == VmKind::kCircle ? VmKind::kSphere : VmKind::kCircle;
    ASSERT_TRUE(parse_vm_kind(vm_kind_name(k), &parsed));
    EXPECT_EQ(parsed, k);
  }
  EXPECT_STREQ(vm_kind_name(VmKind::kCircle), "circle");
  EXPECT_STREQ(vm_kind_name(VmKind::kSphere), "sphere");
  EXPECT_STREQ(vm_kind_name(VmKind::kSurface), "surface");
  EXPECT_STREQ(vm_kind_name(VmKind::kLine), "line");
  EXPECT_EQ(vm_kind_names(), "circle, sphere, surface, line");
  VmKind untouched = VmKind::kSurface;
  for (const char* bad : {"cube", "", "circles", "Sphere", "surface "}) {
    EXPECT_FALSE(parse_vm_kind(bad, &untouched)) << bad;
    EXPECT_EQ(untouched, VmKind::kSurface);
  }
}

TEST(VmKindName, KindAndDof) {
  EXPECT_EQ(CircleVm(VmMount{}, 1.0).dof(), 1);
  EXPECT_EQ(SphereVm(VmMount{}, 1.0).dof(), 3);
  EXPECT_EQ(SurfaceVm(VmMount{}, 1.0).dof(), 5);
  EXPECT_EQ(LineVm(VmMount{}, 1.0).dof(), 1);
  for (const Case& c : all_cases()) {
    EXPECT_EQ(c.vm->zero_angles().size(), c.vm->dof());
    EXPECT_TRUE(c.vm->zero_angles().isZero(0.0));
  }
}

TEST(VmConstruction, RejectsBadParameters) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const VmDescriptor& d : vm_registry()) {
    const VmKind kind = d.kind;
    for (double L : {0.0, -1.0, nan, inf}) {
      EXPECT_THROW(make_vm(kind, VmMount{}, L), std::invalid_argument)
          << vm_kind_name(kind) << " L " << L;
    }
    VmMount scaled;
    scaled.R = 2.0 * Mat3::Identity();
    VmMount reflected;
    reflected.R = Vec3(1, 1, -1).asDiagonal();
    VmMount sheared = turned_mount();
    sheared.R(0, 1) += 1e-3;
    VmMount nan_r;
    nan_r.R(1, 1) = nan;
    VmMount nan_origin;
    nan_origin.origin = Vec3(0, nan, 0);
    VmMount inf_origin;
    inf_origin.origin = Vec3(inf, 0, 0);
    for (const VmMount& m :
         {scaled, reflected, sheared, nan_r, nan_origin, inf_origin}) {
      EXPECT_THROW(make_vm(kind, m, 1.0), std::invalid_argument)
          << vm_kind_name(kind);
    }
    EXPECT_NO_THROW(make_vm(kind, turned_mount(), 1e-6));
  }
}

}  // namespace
}  // namespace vmh
