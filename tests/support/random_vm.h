// Reproducible random draws for the virtual-mechanism tests.
#ifndef VMHAPTICS_TESTS_SUPPORT_RANDOM_VM_H_
#define VMHAPTICS_TESTS_SUPPORT_RANDOM_VM_H_

#include <random>

#include "controller/types.h"
#include "controller/virtual_mechanism.h"

namespace vmh::testing {

inline double uniform(std::mt19937* rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(*rng);
}

// uniform on the unit sphere
inline Vec3 random_unit(std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 v;
  do {
    v = Vec3(n(*rng), n(*rng), n(*rng));
  } while (v.norm() < 1e-6);
  return v.normalized();
}

// random VM angles away from the sphere's and the surface's poles; the
// surface's contact and the line's handle within 2L of the origin
inline VmAngles random_theta(const VirtualMechanism& vm, std::mt19937* rng) {
  constexpr double kPi = 3.14159265358979323846;
  VmAngles t(vm.dof());
  const double L = vm.length();
  switch (vm.kind()) {
    case VmKind::kCircle:
      t << uniform(rng, -kPi, kPi);
      break;
    case VmKind::kSphere:
      t << uniform(rng, -kPi, kPi), uniform(rng, 0.2, kPi - 0.2),
          uniform(rng, -kPi, kPi);
      break;
    case VmKind::kSurface:
      t << uniform(rng, -2 * L, 2 * L), uniform(rng, -2 * L, 2 * L),
          uniform(rng, -kPi, kPi), uniform(rng, 0.2, kPi - 0.2),
          uniform(rng, -kPi, kPi);
      break;
    case VmKind::kLine:
      t << uniform(rng, -2 * L, 2 * L);
      break;
  }
  return t;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_RANDOM_VM_H_
