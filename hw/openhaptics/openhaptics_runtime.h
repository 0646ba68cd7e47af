// OpenHaptics as a device backend of the runtime (runtime/backend_registry.h):
//   openhaptics[:CONFIG]   the vendor's driver through libHD.so, loaded at
//                          run time; CONFIG: the device's configuration
//                          name (empty: the default device)
// Option hd-command: joint_torque (HD_CURRENT_JOINT_TORQUE, mN m; the
// default) or force (HD_CURRENT_FORCE, N).
#ifndef VMHAPTICS_HW_OPENHAPTICS_OPENHAPTICS_RUNTIME_H_
#define VMHAPTICS_HW_OPENHAPTICS_OPENHAPTICS_RUNTIME_H_

#include "runtime/backend_registry.h"

namespace vmh::hw {

void register_openhaptics_backend(runtime::BackendRegistry* registry);

}  // namespace vmh::hw

#endif  // VMHAPTICS_HW_OPENHAPTICS_OPENHAPTICS_RUNTIME_H_
