// The virtual mechanisms' closed-form path (distance_to_path,
// nearest_on_path) against the handle positions their own pose() reaches,
// sampled densely, and the surface's contact (friction cone, unilateral
// lift-off, rest pose) against the cone's definition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "controller/virtual_mechanism.h"
#include "tests/support/random_vm.h"
#include "tests/support/vm_cases.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;

using testing::all_cases;
using testing::Case;
using testing::random_theta;
using testing::random_unit;
using testing::uniform;

// The closed-form path (distance_to_path, nearest_on_path) against the
// handle positions pose(theta) itself reaches: the circle and sphere sampled
// densely, the line over 8L about its origin; for the surface the probe upright (beta = alpha = pi/2, or the
// probe turned over) over every contact point, so its path is the two
// planes L from the plane. The nearest point lies on the path (distance 0),
// is no farther than any sample, and the distance is |p - nearest|.
TEST(VmPath, ClosedFormAgreesWithSampledPoses) {
  std::mt19937 rng(31);
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    const Vec3 o = vm.mount().origin;
    std::vector<Vec3> path;
    VmAngles theta = vm.zero_angles();
    if (vm.kind() == VmKind::kCircle) {
      for (int i = 0; i < 20000; ++i) {
        theta[0] = -kPi + 2 * kPi * i / 20000.0;
        path.push_back(vm.pose(theta).p);
      }
    } else if (vm.kind() == VmKind::kSphere) {
      for (int i = 0; i < 40000; ++i) {
        path.push_back(vm.pose(random_theta(vm, &rng)).p);
      }
    } else if (vm.kind() == VmKind::kLine) {
      // the points tried lie within 3L of the origin
      for (int i = 0; i <= 20000; ++i) {
        theta[0] = -4 * L + 8 * L * i / 20000.0;
        path.push_back(vm.pose(theta).p);
      }
    }
    for (int k = 0; k < 20; ++k) {
      const Vec3 p = o + uniform(&rng, 0.05, 3.0) * L * random_unit(&rng);
      const Vec3 x = vm.nearest_on_path(p);
      const double d = vm.distance_to_path(p);
      EXPECT_NEAR(d, (p - x).norm(), 1e-12 * (1 + L)) << c.name;
      EXPECT_NEAR(vm.distance_to_path(x), 0.0, 1e-12 * (1 + L)) << c.name;
      if (vm.kind() == VmKind::kSurface) {
        // the upright probe whose contact is under p reaches x
        const Vec3 n = vm.mount().R.col(2);
        VmAngles up = vm.rest_angles();
        const Vec3 r = vm.mount().R.transpose() * (p - o);
        up[0] = r.x();
        up[1] = r.y();
        if (r.z() < 0) up[3] = -0.5 * kPi;  // the probe below the plane
        EXPECT_LE((vm.pose(up).p - x).norm(), 1e-12 * (1 + L)) << c.name;
        EXPECT_NEAR(std::abs((x - o).dot(n)), L, 1e-12 * (1 + L)) << c.name;
        continue;
      }
      double best = std::numeric_limits<double>::infinity();
      for (const Vec3& y : path) best = std::min(best, (y - p).norm());
      EXPECT_GE(best, d - 1e-12 * (1 + L)) << c.name;
      EXPECT_LE(best, d + 2e-2 * L) << c.name;
    }
    // the line passes through its origin
    if (vm.kind() == VmKind::kLine) {
      EXPECT_LE((vm.nearest_on_path(o) - o).norm(), 1e-12 * (1 + L));
      EXPECT_NEAR(vm.distance_to_path(o), 0.0, 1e-12 * (1 + L));
    }
    // at the pivot every point of the path is nearest: the pivot is kept
    if (vm.kind() == VmKind::kCircle || vm.kind() == VmKind::kSphere) {
      EXPECT_EQ(vm.nearest_on_path(o), o) << c.name;
      EXPECT_NEAR(vm.distance_to_path(o), L, 1e-12 * (1 + L)) << c.name;
    }
  }
}

// The surface's contact under a force, device frame: the plane pushes and
// holds while the tangential force stays inside mu |f_n|, slides beyond it,
// and a unilateral contact opens when pulled. VMs without a contact hold.
TEST(VmContact, SurfaceFrictionConeAndUnilateral) {
  for (const Case& c : all_cases()) {
    const VirtualMechanism& vm = *c.vm;
    if (vm.kind() != VmKind::kSurface) {
      EXPECT_FALSE(vm.has_contact()) << c.name;
      EXPECT_EQ(vm.stick_joints(), 0u) << c.name;
      EXPECT_EQ(vm.contact_state(Vec3(5, 5, 5), 0.1, true, true),
                ContactState::kClosed)
          << c.name;
      continue;
    }
    EXPECT_TRUE(vm.has_contact());
    EXPECT_EQ(vm.stick_joints(), 3u);  // s1 and s2, the contact point
    const Mat3& R = vm.mount().R;
    const Vec3 n = R.col(2), t = R.col(0);
    const double mu = 0.5;
    // the force on the handle, which stands on the plane's +n side: +n is
    // the plane pushing, -n would need it to pull. 1 N of push: the cone's
    // edge is 0.5 N tangential
    EXPECT_EQ(vm.contact_state(n + 0.49 * t, mu, false, true),
              ContactState::kClosed);
    EXPECT_EQ(vm.contact_state(n + 0.51 * t, mu, false, true),
              ContactState::kSliding);
    // a bilateral contact's cone uses |f_n|: a pull slides the same way
    EXPECT_EQ(vm.contact_state(-n + 0.51 * t, mu, false, true),
              ContactState::kSliding);
    // not sticking (the joints were free): nothing to slide from
    EXPECT_EQ(vm.contact_state(n + 0.51 * t, mu, false, false),
              ContactState::kClosed);
    // pulled toward the plane: open only if unilateral, whatever mu
    EXPECT_EQ(vm.contact_state(-n, mu, true, true), ContactState::kOpen);
    EXPECT_EQ(vm.contact_state(n, mu, true, true), ContactState::kClosed);
    EXPECT_EQ(vm.contact_state(-n + 0.1 * t, mu, false, true),
              ContactState::kClosed);
    // rounding-level forces at rest never slip
    EXPECT_EQ(vm.contact_state(1e-9 * t, 0.0, false, true),
              ContactState::kClosed);
    // the rest pose is the probe upright on the mount's origin
    const VmAngles rest = vm.rest_angles();
    EXPECT_LE((vm.pose(rest).p - (vm.mount().origin + vm.length() * n)).norm(),
              1e-12 * (1 + vm.length()));
  }
}

}  // namespace
}  // namespace vmh
