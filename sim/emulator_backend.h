// The emulator as device backends of the runtime (runtime/backend_registry.h):
//   emulator[:case|scene.xml]           the MuJoCo Omni (sim/emulator.h)
//   emulator:firewire[:case|scene.xml]  the same behind the FireWire Omni's
//                                       packets (sim/emulator_firewire.h)
//                                       and the native driver's device
//                                       layer (hw/firewire/)
// Both run on the wall clock (the emulator's physics thread and the
// project's servo thread) or in lockstep (OpenRequest::lockstep: no
// thread, one period of physics per tick: device/lockstep.h), and both
// give the session the plant's truth, the hand programs and the raw
// calibration.
//
// Options (OpenRequest::options): hand (the hand program), fault (injected
// transport or packet faults), emulator-fault (seeded faults), model (a
// calibrated Omni MJCF). The scene's --set overrides are
// OpenRequest::scene_sets.
#ifndef VMHAPTICS_SIM_EMULATOR_BACKEND_H_
#define VMHAPTICS_SIM_EMULATOR_BACKEND_H_

#include "runtime/backend_registry.h"

namespace vmh::sim {

// Registers "emulator" and "emulator:firewire".
void register_backends(runtime::BackendRegistry* registry);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_BACKEND_H_
