#include "hw/backends.h"

#include "hw/firewire/firewire_runtime.h"
#include "hw/openhaptics/openhaptics_runtime.h"
#include "hw/served/served_runtime.h"
#include "hw/replay/replay_runtime.h"
#include "hw/usb/usb_runtime.h"

namespace vmh::hw {

void register_backends(runtime::BackendRegistry* registry) {
  register_openhaptics_backend(registry);
  fw::register_firewire_backend(registry);
  usb::register_usb_backend(registry);
  served::register_served_backend(registry);
  replay::register_replay_backend(registry);
}

}  // namespace vmh::hw
