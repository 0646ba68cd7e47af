// Loads the vendor's libHD.so at run time, so that the project builds and
// runs without the OpenHaptics SDK. Which file: the exact path in the
// environment variable VMH_LIBHD if it is set and not empty, else
// "libHD.so" through the dynamic loader's own search (LD_LIBRARY_PATH,
// the directories of /etc/ld.so.cache, then /lib and /usr/lib). Nothing
// else is tried, so a library cannot be picked up by accident.
#ifndef VMHAPTICS_HW_OPENHAPTICS_HD_LIBRARY_H_
#define VMHAPTICS_HW_OPENHAPTICS_HD_LIBRARY_H_

#include <string>

#include "hw/dl_library.h"
#include "hw/openhaptics/hd_api.h"

namespace vmh::hw::hd {

class HdLibrary {
 public:
  static constexpr const char* kDefaultName = "libHD.so";
  static constexpr const char* kPathVariable = "VMH_LIBHD";

  // Loads from VMH_LIBHD or the search path. Throws vmh::DeviceOpenError
  // (device/device_backend.h) with one line naming what was looked for and
  // the loader's reason, or the symbol that is missing.
  HdLibrary();
  // Loads `file`: a path (it contains '/') or a bare name for the loader to
  // search for.
  explicit HdLibrary(const std::string& file);
  HdLibrary(const HdLibrary&) = delete;
  HdLibrary& operator=(const HdLibrary&) = delete;

  const HdApi& api() const noexcept { return api_; }
  // what was loaded: VMH_LIBHD's value or "libHD.so"
  const std::string& file() const noexcept { return dl_.file(); }

  // One line for `hw list`: what a load would try now.
  static std::string describe_search();

 private:
  DlLibrary dl_;
  HdApi api_;
};

}  // namespace vmh::hw::hd

#endif  // VMHAPTICS_HW_OPENHAPTICS_HD_LIBRARY_H_
