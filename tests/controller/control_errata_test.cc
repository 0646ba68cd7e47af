// Errata of the thesis's chapter 3 and Appendix D (the control law and the
// C++ that ran on the device), each shown with numbers. docs/errata.md lists
// them (entries 23-29).
//
// The listing's expressions are typed here as printed (namespace `listing`),
// in double rather than float. The truths are geometric: a point of the
// sphere lies at distance L from its pivot; a rotation's effect is read off
// Eigen's AngleAxis; the VM joint axes are finite differences of the frame.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "controller/controller.h"
#include "controller/omni_kinematics.h"
#include "controller/virtual_mechanism.h"
#include "controller/vm_circle.h"
#include "controller/vm_line.h"
#include "controller/vm_registry.h"
#include "controller/vm_sphere.h"
#include "controller/vm_surface.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;

// Appendix D, typed as printed (PI for the listing's PI)
namespace listing {

// listing D.5, lines 9-10: the VM angles from the RM position
double theta_v1(const Vec3& pos, const Vec3& pivot) {
  return std::atan2(pos[1] - pivot[1], pos[0] - pivot[0]);
}
double theta_v2(const Vec3& pos, const Vec3& pivot) {
  const double LL = (pos - pivot).norm();
  return -kPi - std::acos((pos[2] - pivot[2]) / LL);
}
// listing D.5, lines 18-20
Vec3 position_error(const Vec3& pos, const Vec3& pivot, double Lv) {
  const Vec3 p = pivot;
  const double t1 = theta_v1(pos, pivot), t2 = theta_v2(pos, pivot);
  Vec3 e;
  e[0] = p[0] + Lv * std::sin(t2) * std::cos(t1) - pos[0];
  e[1] = p[1] + Lv * std::sin(t2) * std::sin(t1) + p[1] - pos[1];
  e[2] = p[2] - Lv * std::cos(t2) - pos[2];
  return e;
}
// listing D.1, line 11
double orientation_gain(double Kp1, double Lv) { return Kp1 * 3.14 * Lv; }

}  // namespace listing

Vec3 random_point(std::mt19937* rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return Vec3(u(*rng), u(*rng), u(*rng));
}

// 23. Listing D.5 line 19 adds pivotLoc[1] twice. With the pivot at the
// device origin, as in the thesis's runs, the slip is invisible; anywhere
// else the VM point leaves the sphere.
TEST(ControlErrata, ListingD5DoublesPivotY) {
  std::mt19937 rng(23);
  const double L = 50.0;
  for (int k = 0; k < 200; ++k) {
    const Vec3 pivot = random_point(&rng, 40.0);
    const Vec3 pos = pivot + random_point(&rng, 80.0);
    // the listing's VM point X_V = pos + e
    const Vec3 x_listing = pos + listing::position_error(pos, pivot, L);
    // off the sphere by the doubled term
    const Vec3 fixed = x_listing - Vec3(0, pivot.y(), 0);
    EXPECT_NEAR((fixed - pivot).norm(), L, 1e-9);
    if (std::abs(pivot.y()) > 1.0) {
      EXPECT_GT(std::abs((x_listing - pivot).norm() - L), 1e-3);
    }
    // the project's placement lies on the sphere, at the nearest point
    VmMount mount;
    mount.origin = pivot;
    const SphereVm vm(mount, L);
    VmAngles theta = vm.zero_angles();
    ASSERT_TRUE(vm.nearest(RmPose{pos, Vec3::UnitZ()}, &theta));
    const Vec3 x = vm.pose(theta).p;
    EXPECT_NEAR((x - pivot).norm(), L, 1e-9);
    EXPECT_LT((x - fixed).norm(), 1e-9);  // = the listing without the slip
  }
  // at the thesis's pivot (the origin) the listing is right
  const Vec3 pos(20, -30, 45);
  EXPECT_NEAR((pos + listing::position_error(pos, Vec3::Zero(), L)).norm(), L,
              1e-12);
}

// 24. theta_V2: the text's pi - acos(..) and the listing's -pi - acos(..)
// differ by 2 pi and place the VM at the same point; a difference of one
// with the other is off by 2 pi unless it is wrapped, as the project does.
TEST(ControlErrata, ThetaV2ListingAndTextDifferByTwoPi) {
  std::mt19937 rng(24);
  const double L = 50.0;
  for (int k = 0; k < 200; ++k) {
    const Vec3 pos = random_point(&rng, 80.0);
    const double text = kPi - std::acos(pos.z() / pos.norm());
    const double list = listing::theta_v2(pos, Vec3::Zero());
    EXPECT_NEAR(text - list, 2 * kPi, 1e-12);
    // same point: eq. 3.30's z and the sin(theta2) factor of x and y
    EXPECT_NEAR(-L * std::cos(text), -L * std::cos(list), 1e-9);
    EXPECT_NEAR(std::sin(text), std::sin(list), 1e-12);
    // an error mixing the two is 2 pi off (above) unless wrapped
    EXPECT_NEAR(wrap_angle(text - list), 0.0, 1e-12);
  }
}

// 25. Listing D.1's orientation gain is Kp * 3.14 * L: half eq. 3.28's
// circumference 2 pi L, with pi rounded.
TEST(ControlErrata, ListingD1GainIsHalfTheCircumference) {
  const double ratio = listing::orientation_gain(0.5, 50.0) /
                       thesis_orientation_gain(0.5, 50.0);
  EXPECT_NEAR(ratio, 3.14 / (2 * kPi), 1e-15);
  EXPECT_LT(std::abs(ratio - 0.5), 3e-4);
}

// 26. Eq. 3.35-3.37 subtract angles, (0, d theta2, d theta1) in the
// (x, y, z) rows, but eq. 3.31's rows 4-6 are angular velocities: theta2
// turns the link about (sin theta1, -cos theta1, 0). For a small polar
// misalignment the rotation that carries the VM onto the stylus is
// d theta2 about that axis; the thesis's row is d theta2 about y. They
// agree only at theta1 = -pi/2 (and are opposite at theta1 = 0).
TEST(ControlErrata, EulerAngleErrorIsNotTheAngularVelocityRows) {
  const SphereVm vm(VmMount{}, 50.0);
  const double d = 1e-4;
  for (double t1 : {-kPi / 2, 0.0, 0.7, kPi / 2, 2.5}) {
    VmAngles tv(3), tr(3);
    tv << t1, 1.2, 0.0;
    tr << t1, 1.2 - d, 0.0;  // the stylus a little nearer the -z pole
    const Vec3 thesis = vm.thesis_orientation_error(tv, tr);
    // the rotation carrying the stylus axis onto the VM axis, from Eigen
    const Vec3 a = vm.pose(tr).axis, u = vm.pose(tv).axis;
    const Eigen::AngleAxisd rot(Eigen::Quaterniond::FromTwoVectors(a, u));
    const Vec3 truth = rot.angle() * rot.axis();
    EXPECT_NEAR(truth.norm(), d, 1e-9);
    EXPECT_LT((truth - d * Vec3(std::sin(t1), -std::cos(t1), 0)).norm(),
              1e-9);
    EXPECT_LT((thesis - d * Vec3::UnitY()).norm(), 1e-12);
    const double cos_between = thesis.dot(truth) / (d * d);
    EXPECT_NEAR(cos_between, -std::cos(t1), 1e-6) << "theta1 " << t1;
  }
}

// 27. Eq. 3.24 writes theta_V = atan(e_y / e_x) with e the error; the
// nearest point's angle is atan2(Y - Y0, X - X0) of the RM (as §3.3.1 and
// listing D.4 have it), which eq. 3.24 gives only by accident.
TEST(ControlErrata, Eq3Dot24UsesTheErrorInsteadOfThePosition) {
  const double L = 50.0;
  const Vec3 rm(30.0, 40.0, 0.0);  // nearest angle atan2(40, 30)
  const double nearest = std::atan2(40.0, 30.0);
  int wrong = 0;
  for (double t0 : {-2.0, -0.5, 0.3, 1.5, 2.8}) {
    const Vec3 x_v(L * std::cos(t0), L * std::sin(t0), 0.0);
    const Vec3 e = x_v - rm;  // eq. 3.9
    const double eq324 = std::atan(e.y() / e.x());
    if (std::abs(wrap_angle(eq324 - nearest)) > 1e-3) ++wrong;
  }
  EXPECT_GE(wrong, 4);
  const CircleVm vm(VmMount{}, L);
  VmAngles t = vm.zero_angles();
  ASSERT_TRUE(vm.nearest(RmPose{rm, Vec3::UnitZ()}, &t));
  EXPECT_NEAR(t[0], nearest, 1e-15);
}

}  // namespace
}  // namespace vmh
