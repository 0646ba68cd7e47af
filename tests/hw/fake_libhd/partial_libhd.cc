// A library with only some of the HD API's symbols, so that the loader's
// missing-symbol error can be tested (tests/hw/hd_library_test.cc).
#include "hw/openhaptics/hd_api.h"

using namespace vmh::hw::hd;  // NOLINT

extern "C" __attribute__((visibility("default"))) HHD hdInitDevice(HDstring) {
  return kInvalidHandle;
}
extern "C" __attribute__((visibility("default"))) void hdDisableDevice(HHD) {}
extern "C" __attribute__((visibility("default"))) void hdMakeCurrentDevice(HHD) {}
