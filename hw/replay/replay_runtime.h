// A recording as a device backend of the runtime (runtime/backend_registry.h):
//   replay:DIR   the folder `vmhaptics hw record --out DIR` wrote
// with options replay-end=hold|loop|stop (what reads give after the last
// row; default hold) and replay-speed=F (recording seconds per second,
// default 1). It runs on either clock (BackendInfo::lockstep) and has no
// discovery: `hw list` says to give a recording folder.
#ifndef VMHAPTICS_HW_REPLAY_REPLAY_RUNTIME_H_
#define VMHAPTICS_HW_REPLAY_REPLAY_RUNTIME_H_

#include <string>

#include "hw/replay/replay_device.h"
#include "runtime/backend_registry.h"

namespace vmh::hw::replay {

void register_replay_backend(runtime::BackendRegistry* registry);

// The request's replay options. Throws runtime::RequestError naming the bad
// option or value.
ReplayOptions replay_options(const runtime::OpenRequest& rq);

// meta.json's "replay": the recording, the options, what was served and
// what was written
Json replay_meta_json(const ReplayDevice& device);

}  // namespace vmh::hw::replay

#endif  // VMHAPTICS_HW_REPLAY_REPLAY_RUNTIME_H_
