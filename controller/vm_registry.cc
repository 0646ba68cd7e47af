#include "controller/vm_registry.h"

#include <stdexcept>

#include "controller/vm_circle.h"
#include "controller/vm_line.h"
#include "controller/vm_sphere.h"
#include "controller/vm_surface.h"

namespace vmh {
namespace {

template <class Vm>
std::unique_ptr<VirtualMechanism> make(const VmMount& mount, double length) {
  return std::make_unique<Vm>(mount, length);
}

}  // namespace

const std::vector<VmDescriptor>& vm_registry() {
  // one row per mechanism, in the order of VmKind
  static const std::vector<VmDescriptor> registry = {
      {VmKind::kCircle, "circle", 1,
       "a link of length L turning about the pivot in a plane (thesis "
       "§3.3, eq. 3.25-3.27)",
       "circle", "4.1-4.2", &make<CircleVm>, &predict_circle},
      {VmKind::kSphere, "sphere", 3,
       "a link of length L on a ball joint at the pivot (thesis §3.4, "
       "eq. 3.29-3.31)",
       "sphere (outline)", "4.13-4.18", &make<SphereVm>, &predict_sphere},
      {VmKind::kSurface, "surface", 5,
       "a probe of length L whose tip slides on a plane, a ball joint at "
       "the tip (thesis §3.1)",
       "surface (plane + L)", "", &make<SurfaceVm>, nullptr},
      {VmKind::kLine, "line", 1,
       "a handle sliding on a straight line: the circle's limit as its "
       "radius grows (this project's, docs/control.md)",
       "line", "", &make<LineVm>, &predict_line},
  };
  return registry;
}

const VmDescriptor& vm_descriptor(VmKind kind) {
  for (const VmDescriptor& d : vm_registry()) {
    if (d.kind == kind) return d;
  }
  throw std::invalid_argument("virtual mechanism: kind " +
                              std::to_string(static_cast<int>(kind)) +
                              " is not registered");
}

const VmDescriptor* find_vm(const std::string& name) {
  for (const VmDescriptor& d : vm_registry()) {
    if (name == d.name) return &d;
  }
  return nullptr;
}

std::string vm_kind_names() {
  std::string out;
  for (const VmDescriptor& d : vm_registry()) {
    if (!out.empty()) out += ", ";
    out += d.name;
  }
  return out;
}

const char* vm_kind_name(VmKind kind) {
  for (const VmDescriptor& d : vm_registry()) {
    if (d.kind == kind) return d.name;
  }
  return "unknown";
}

bool parse_vm_kind(const char* text, VmKind* kind) {
  const VmDescriptor* d = find_vm(text);
  if (d == nullptr) return false;
  *kind = d->kind;
  return true;
}

std::unique_ptr<VirtualMechanism> make_vm(VmKind kind, const VmMount& mount,
                                          double length) {
  return vm_descriptor(kind).make(mount, length);
}

}  // namespace vmh
