// The virtual mechanisms the controller tests run over: every registered
// kind (all_cases), or those named, each with the
// default mount and a pivot away from the origin in a turned frame, at a
// long (50) and a short (0.05) link.
#ifndef VMHAPTICS_TESTS_SUPPORT_VM_CASES_H_
#define VMHAPTICS_TESTS_SUPPORT_VM_CASES_H_

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "controller/virtual_mechanism.h"
#include "controller/vm_circle.h"
#include "controller/vm_line.h"
#include "controller/vm_registry.h"
#include "controller/vm_sphere.h"
#include "controller/vm_surface.h"

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

// kinds x {default mount, turned mount} x {50, 0.05}
inline std::vector<Case> cases(std::vector<VmKind> kinds) {
  std::vector<Case> out;
  for (VmKind kind : kinds) {
    for (int turned = 0; turned < 2; ++turned) {
      for (double L : {50.0, 0.05}) {
        const VmMount mount = turned ? turned_mount() : VmMount{};
        out.push_back({vmh::make_vm(kind, mount, L),
                       std::string(vm_kind_name(kind)) +
                           (turned ? " turned" : " default") +
                           " L=" + std::to_string(L)});
      }
    }
  }
  return out;
}

// every registered kind (controller/vm_registry.h)
inline std::vector<Case> all_cases() {
  std::vector<VmKind> kinds;
  for (const VmDescriptor& d : vm_registry()) kinds.push_back(d.kind);
  return cases(kinds);
}


}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_VM_CASES_H_
