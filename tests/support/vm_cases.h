// The virtual mechanisms the controller tests run over: every kind, with the
// default mount and a pivot away from the origin in a turned frame, at a
// long (50) and a short (0.05) link.
#ifndef VMHAPTICS_TESTS_SUPPORT_VM_CASES_H_
#define VMHAPTICS_TESTS_SUPPORT_VM_CASES_H_

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "controller/virtual_mechanism.h"

namespace vmh::testing {

inline VmMount turned_mount() {
  VmMount m;
  m.origin = Vec3(10.0, -20.0, 5.0);
  m.R = Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, -0.5).normalized())
            .toRotationMatrix();
  return m;
}

struct Case {
  std::unique_ptr<VirtualMechanism> vm;
  std::string name;
};

inline std::unique_ptr<VirtualMechanism> make_vm(VmKind kind, const VmMount& mount,
                                          double L) {
  switch (kind) {
    case VmKind::kCircle:
      return std::make_unique<CircleVm>(mount, L);
    case VmKind::kSphere:
      return std::make_unique<SphereVm>(mount, L);
    case VmKind::kSurface:
      return std::make_unique<SurfaceVm>(mount, L);
  }
  return nullptr;
}

// kinds x {default mount, turned mount} x {50, 0.05}
inline std::vector<Case> cases(std::vector<VmKind> kinds) {
  std::vector<Case> out;
  for (VmKind kind : kinds) {
    for (int turned = 0; turned < 2; ++turned) {
      for (double L : {50.0, 0.05}) {
        const VmMount mount = turned ? turned_mount() : VmMount{};
        out.push_back({make_vm(kind, mount, L),
                       std::string(vm_kind_name(kind)) +
                           (turned ? " turned" : " default") +
                           " L=" + std::to_string(L)});
      }
    }
  }
  return out;
}

inline std::vector<Case> all_cases() {
  return cases({VmKind::kCircle, VmKind::kSphere, VmKind::kSurface});
}


}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_VM_CASES_H_
