// libraw1394, loaded at run time (dlopen), as the OpenHaptics library is
// (hw/openhaptics/hd_library.h). Which file: the exact path in the
// environment variable VMH_LIBRAW1394 when it is set and not empty, else
// "libraw1394.so.11" (the soname of libraw1394 2.x, Debian's libraw1394-11)
// through the dynamic loader's own search. Nothing else is tried, so that a
// test library is reached only when a test names it.
//
// Why at run time: a build then needs no libraw1394-dev, the program runs
// (and `hw list` says why not) on a machine without the library, and a
// test points one process at its libraw1394 stand-in
// (tests/hw/firewire/fwsim/) by setting one variable, without touching the
// loader's search path.
//
// A loaded library is shared by every transport of the process and stays
// loaded while one of them holds it.
#ifndef VMHAPTICS_HW_FIREWIRE_RAW1394_LIBRARY_H_
#define VMHAPTICS_HW_FIREWIRE_RAW1394_LIBRARY_H_

#include <memory>
#include <string>

#include "hw/dl_library.h"
#include "hw/firewire/raw1394_api.h"

namespace vmh::hw::fw {

class Raw1394Library {
 public:
  static constexpr const char* kDefaultName = "libraw1394.so.11";
  static constexpr const char* kPathVariable = "VMH_LIBRAW1394";

  // The library VMH_LIBRAW1394 names, or the default one; `file` (a path or
  // a bare name for the loader to search) when not empty. Loaded once per
  // file and process. Throws vmh::DeviceOpenError with one line naming what
  // was looked for and the loader's reason, or the missing symbol.
  static std::shared_ptr<const Raw1394Library> load(const std::string& file = {});

  Raw1394Library(const Raw1394Library&) = delete;
  Raw1394Library& operator=(const Raw1394Library&) = delete;

  const r1394::Api& api() const noexcept { return api_; }
  // what was loaded: VMH_LIBRAW1394's value or the default name
  const std::string& file() const noexcept { return dl_.file(); }
  // a symbol of the library beyond the API (a test library's own), or null
  void* symbol(const char* name) const noexcept;

  // one line for `hw list`: what a load would try now
  static std::string describe_search();

 private:
  explicit Raw1394Library(const DlChoice& choice);
  DlLibrary dl_;
  r1394::Api api_{};
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_RAW1394_LIBRARY_H_
