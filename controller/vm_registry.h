// The virtual mechanisms, each registered once (as mujoco_mpc lists its
// tasks): the name a scene gives in `vm_kind`, its joints, a factory, and
// its prediction hook. Drawing and scripting go through the mechanism's own
// virtual hooks (path_primitives, planar, path_start, along_path in
// controller/virtual_mechanism.h), so the figures, the viewer, the hand
// scripts, the case fields and the law's prediction switch on no kind.
//
// Adding a mechanism: its own vm_<name>.{h,cc}, a VmKind value, and one row
// in vm_registry.cc (docs/control.md, "Adding a virtual mechanism").
#ifndef VMHAPTICS_CONTROLLER_VM_REGISTRY_H_
#define VMHAPTICS_CONTROLLER_VM_REGISTRY_H_

#include <memory>
#include <string>
#include <vector>

#include "controller/virtual_mechanism.h"

namespace vmh {

// The law's static placement in closed form at the pose rm (device frame,
// the VM's length unit), with the thesis's orientation error if
// `thesis_error`, else the geometric one. false, with *why_not set, where
// the placement is not defined there.
using VmPredictFn = bool (*)(const VirtualMechanism& vm, const RmPose& rm,
                             bool thesis_error, VmStaticPlacement* out,
                             const char** why_not);

struct VmDescriptor {
  VmKind kind;
  const char* name;     // the scenes' vm_kind: "circle"
  int dof;
  const char* summary;  // one line: what it is and where it comes from
  // the figures' legend for its path ("circle", "sphere (outline)")
  const char* path_label;
  // the thesis's figures it reproduces ("" for none)
  const char* thesis_figures;
  std::unique_ptr<VirtualMechanism> (*make)(const VmMount& mount,
                                            double length);
  VmPredictFn predict;  // nullptr: no closed form
};

// every registered mechanism, in the order of VmKind
const std::vector<VmDescriptor>& vm_registry();
// throws std::invalid_argument for a value with no row
const VmDescriptor& vm_descriptor(VmKind kind);
// by name; nullptr for an unknown one
const VmDescriptor* find_vm(const std::string& name);
// "circle, sphere, surface, line": the names, for messages and docs
std::string vm_kind_names();

// "circle", ...; "unknown" for a value not registered
const char* vm_kind_name(VmKind kind);
// parses a registered name; false for anything else
bool parse_vm_kind(const char* text, VmKind* kind);

// the mechanism of `kind` (throws std::invalid_argument, from the
// mechanism's constructor, for a bad mount or length)
std::unique_ptr<VirtualMechanism> make_vm(VmKind kind, const VmMount& mount,
                                          double length);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VM_REGISTRY_H_
