// A vendor library loaded at run time (dlopen), by the one rule the
// project's loaders share (hw/openhaptics/hd_library.h for libHD.so,
// hw/firewire/raw1394_library.h for libraw1394): the exact path in an
// environment variable when it is set and not empty (a bare name there
// means the working directory), else a default name through the dynamic
// loader's own search. Nothing else is tried, so that a test library is
// reached only when a test names it.
//
// Errors are vmh::DeviceOpenError with one line: what was looked for and
// the loader's reason, or the symbol that is missing. Header-only: each
// loader's library links libdl itself.
#ifndef VMHAPTICS_HW_DL_LIBRARY_H_
#define VMHAPTICS_HW_DL_LIBRARY_H_

#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <type_traits>

#include "device/device_backend.h"

namespace vmh::hw {

// Where a loader looks, and the words of its messages.
struct DlSearch {
  const char* backend;       // the messages' prefix: "firewire"
  const char* variable;      // "VMH_LIBRAW1394"
  const char* default_name;  // "libraw1394.so.11"
  const char* where;         // the search's places: "Debian: libraw1394-11"
  const char* what_it_is;    // after a missing symbol: "is it libraw1394 2.x?"
};

// Which file a load opens, and whether the variable named it.
struct DlChoice {
  std::string file;
  bool from_env = false;
};

class DlLibrary {
 public:
  // `file` (a path, or a bare name for the loader's search) when not empty,
  // else the variable's value, else the default name.
  static DlChoice choose(const DlSearch& search, const std::string& file) {
    DlChoice c{file, false};
    if (c.file.empty()) {
      c.file = from_environment(search);
      c.from_env = !c.file.empty();
      if (!c.from_env) c.file = search.default_name;
    }
    return c;
  }

  // Loads choose(search, file). Throws DeviceOpenError: "<backend>: cannot
  // load <what was looked for>: <reason>".
  DlLibrary(const DlSearch& search, const std::string& file)
      : DlLibrary(search, choose(search, file)) {}
  DlLibrary(const DlSearch& search, const DlChoice& choice)
      : search_(search), file_(choice.file) {
    std::string to_open = file_;
    if (choice.from_env && to_open.find('/') == std::string::npos) {
      to_open = "./" + to_open;
    }
    dlerror();
    handle_ = dlopen(to_open.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle_ == nullptr) {
      throw DeviceOpenError(std::string(search.backend) + ": cannot load " +
                            looked_for(search, file_, choice.from_env) + ": " +
                            last_error());
    }
  }
  ~DlLibrary() {
    if (handle_ != nullptr) dlclose(handle_);
  }
  DlLibrary(const DlLibrary&) = delete;
  DlLibrary& operator=(const DlLibrary&) = delete;

  // what was loaded: the variable's value, `file` or the default name
  const std::string& file() const noexcept { return file_; }

  // Sets *slot to the function `name`. Throws DeviceOpenError:
  // "<backend>: <file> has no symbol <name> (<what_it_is>): <reason>".
  template <typename Fn>
  void resolve(const char* name, Fn* slot) const {
    static_assert(std::is_pointer_v<Fn>, "resolve into a function pointer");
    dlerror();
    void* sym = dlsym(handle_, name);
    if (sym == nullptr) {
      throw DeviceOpenError(std::string(search_.backend) + ": " + file_ +
                            " has no symbol " + name + " (" + search_.what_it_is +
                            "): " + last_error());
    }
    // POSIX guarantees that a pointer from dlsym converts to a function
    // pointer
    *slot = reinterpret_cast<Fn>(sym);
  }
  // a symbol that may be absent: null then (dlerror cleared)
  void* symbol(const char* name) const noexcept {
    void* sym = dlsym(handle_, name);
    dlerror();
    return sym;
  }

  // One line for `hw list`: what a load would try now.
  static std::string describe_search(const DlSearch& search) {
    const std::string env = from_environment(search);
    if (!env.empty()) return std::string(search.variable) + "=" + env;
    return looked_for(search, search.default_name, false);
  }

 private:
  // the variable's value, or empty when it is unset or empty
  static std::string from_environment(const DlSearch& search) {
    const char* v = std::getenv(search.variable);
    return v != nullptr ? std::string(v) : std::string();
  }
  static std::string looked_for(const DlSearch& search, const std::string& file,
                                bool from_env) {
    if (from_env) return std::string(search.variable) + "=" + file;
    if (file.find('/') != std::string::npos) return file;
    return file + " on the loader's search path (" + search.where + "; or set " +
           search.variable + " to its path)";
  }
  static std::string last_error() {
    const char* e = dlerror();
    return e != nullptr ? std::string(e) : std::string("no reason given");
  }

  DlSearch search_;
  void* handle_ = nullptr;
  std::string file_;
};

}  // namespace vmh::hw

#endif  // VMHAPTICS_HW_DL_LIBRARY_H_
