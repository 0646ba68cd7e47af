#include "hw/firewire/raw1394_library.h"

#include <dlfcn.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <type_traits>

#include "device/device_backend.h"

namespace vmh::hw::fw {

namespace {

// VMH_LIBRAW1394's value, or empty when it is unset or empty
std::string path_from_environment() {
  const char* v = std::getenv(Raw1394Library::kPathVariable);
  return v != nullptr ? std::string(v) : std::string();
}

std::string what_was_looked_for(const std::string& file, bool from_env) {
  if (from_env) return std::string(Raw1394Library::kPathVariable) + "=" + file;
  if (file.find('/') != std::string::npos) return file;
  return file +
         " on the loader's search path (Debian: libraw1394-11; or set " +
         Raw1394Library::kPathVariable + " to its path)";
}

std::string last_dl_error() {
  const char* e = dlerror();
  return e != nullptr ? std::string(e) : std::string("no reason given");
}

}  // namespace

std::shared_ptr<const Raw1394Library> Raw1394Library::load(const std::string& file_in) {
  bool from_env = false;
  std::string file = file_in;
  if (file.empty()) {
    file = path_from_environment();
    from_env = !file.empty();
    if (!from_env) file = kDefaultName;
  }
  // one instance per file: every transport and listing of the process, and
  // a test's own handle on its stand-in, see the same library
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<const Raw1394Library>> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  if (auto it = loaded.find(file); it != loaded.end()) {
    if (auto lib = it->second.lock()) return lib;
  }

  // VMH_LIBRAW1394 is an exact path: a bare name there means the working
  // directory, not the loader's search
  std::string to_open = file;
  if (from_env && to_open.find('/') == std::string::npos) to_open = "./" + to_open;
  std::shared_ptr<Raw1394Library> lib(new Raw1394Library);
  lib->file_ = file;
  dlerror();
  lib->handle_ = dlopen(to_open.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib->handle_ == nullptr) {
    throw DeviceOpenError("firewire: cannot load " +
                          what_was_looked_for(file, from_env) + ": " +
                          last_dl_error());
  }
  const auto resolve = [&](const char* name, auto* slot) {
    dlerror();
    void* sym = dlsym(lib->handle_, name);
    if (sym == nullptr) {
      throw DeviceOpenError("firewire: " + file + " has no symbol " + name +
                            " (is it libraw1394 2.x?): " + last_dl_error());
    }
    // POSIX guarantees that a pointer from dlsym converts to a function
    // pointer
    *slot = reinterpret_cast<std::remove_pointer_t<decltype(slot)>>(sym);
  };
  r1394::Api& a = lib->api_;
#define VMH_RAW1394_RESOLVE(fn) resolve("raw1394_" #fn, &a.fn)
  VMH_RAW1394_RESOLVE(new_handle);
  VMH_RAW1394_RESOLVE(new_handle_on_port);
  VMH_RAW1394_RESOLVE(destroy_handle);
  VMH_RAW1394_RESOLVE(get_port_info);
  VMH_RAW1394_RESOLVE(get_nodecount);
  VMH_RAW1394_RESOLVE(get_local_id);
  VMH_RAW1394_RESOLVE(get_generation);
  VMH_RAW1394_RESOLVE(update_generation);
  VMH_RAW1394_RESOLVE(set_userdata);
  VMH_RAW1394_RESOLVE(get_userdata);
  VMH_RAW1394_RESOLVE(get_fd);
  VMH_RAW1394_RESOLVE(loop_iterate);
  VMH_RAW1394_RESOLVE(set_bus_reset_handler);
  VMH_RAW1394_RESOLVE(busreset_notify);
  VMH_RAW1394_RESOLVE(read);
  VMH_RAW1394_RESOLVE(write);
  VMH_RAW1394_RESOLVE(channel_modify);
  VMH_RAW1394_RESOLVE(iso_recv_init);
  VMH_RAW1394_RESOLVE(iso_recv_start);
  VMH_RAW1394_RESOLVE(iso_xmit_init);
  VMH_RAW1394_RESOLVE(iso_xmit_start);
  VMH_RAW1394_RESOLVE(iso_stop);
  VMH_RAW1394_RESOLVE(iso_shutdown);
#undef VMH_RAW1394_RESOLVE
  loaded[file] = lib;
  return lib;
}

Raw1394Library::~Raw1394Library() {
  if (handle_ != nullptr) dlclose(handle_);
}

void* Raw1394Library::symbol(const char* name) const noexcept {
  return handle_ != nullptr ? dlsym(handle_, name) : nullptr;
}

std::string Raw1394Library::describe_search() {
  const std::string env = path_from_environment();
  if (!env.empty()) return std::string(kPathVariable) + "=" + env;
  return what_was_looked_for(kDefaultName, false);
}

}  // namespace vmh::hw::fw
