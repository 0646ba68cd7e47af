// The served device as a backend of the runtime (runtime/backend_registry.h):
//   served:NAME   a device another process serves under NAME
//                 (`vmhaptics view --serve-hd NAME`), through
//                 /dev/shm/vmhaptics-hd-NAME (hw/served/served_device.h)
#ifndef VMHAPTICS_HW_SERVED_SERVED_RUNTIME_H_
#define VMHAPTICS_HW_SERVED_SERVED_RUNTIME_H_

#include "runtime/backend_registry.h"

namespace vmh::hw::served {

void register_served_backend(runtime::BackendRegistry* registry);

}  // namespace vmh::hw::served

#endif  // VMHAPTICS_HW_SERVED_SERVED_RUNTIME_H_
