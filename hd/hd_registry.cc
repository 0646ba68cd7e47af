#include "hd/hd_registry.h"

#include "hw/backends.h"
#ifdef VMH_HD_WITH_SIM
#include "sim/emulator_backend.h"
#endif

namespace vmh::hd {

const runtime::BackendRegistry& library_registry() {
  static const runtime::BackendRegistry* registry = [] {
    auto* r = new runtime::BackendRegistry;
    hw::register_backends(r);
#ifdef VMH_HD_WITH_SIM
    sim::register_backends(r);
#endif
    return r;
  }();
  return *registry;
}

}  // namespace vmh::hd
