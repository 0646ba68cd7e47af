// The device backends of hw/, registered with the runtime
// (runtime/backend_registry.h): one line each in hw/backends.cc. The
// emulator's are registered from sim/ (sim/emulator_backend.h).
#ifndef VMHAPTICS_HW_BACKENDS_H_
#define VMHAPTICS_HW_BACKENDS_H_

#include "runtime/backend_registry.h"

namespace vmh::hw {

// openhaptics, firewire, usb, served, replay
void register_backends(runtime::BackendRegistry* registry);

}  // namespace vmh::hw

#endif  // VMHAPTICS_HW_BACKENDS_H_
