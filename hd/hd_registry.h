// The backends the open HD API opens devices from: the library's own
// registry (runtime/backend_registry.h), filled once with hw/'s backends
// and, in a build with the testbed, the emulators. Private to the library:
// a program that loads libHD.so and has a registry of its own (vmhaptics
// itself, through --device openhaptics) keeps its own.
#ifndef VMHAPTICS_HD_HD_REGISTRY_H_
#define VMHAPTICS_HD_HD_REGISTRY_H_

#include "runtime/backend_registry.h"

namespace vmh::hd {

const runtime::BackendRegistry& library_registry();

}  // namespace vmh::hd

#endif  // VMHAPTICS_HD_HD_REGISTRY_H_
