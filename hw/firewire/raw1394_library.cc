#include "hw/firewire/raw1394_library.h"

#include <map>
#include <mutex>

namespace vmh::hw::fw {

namespace {

const DlSearch kSearch{"firewire", Raw1394Library::kPathVariable,
                       Raw1394Library::kDefaultName, "Debian: libraw1394-11",
                       "is it libraw1394 2.x?"};

}  // namespace

Raw1394Library::Raw1394Library(const DlChoice& choice) : dl_(kSearch, choice) {
  r1394::Api& a = api_;
#define VMH_RAW1394_RESOLVE(fn) dl_.resolve("raw1394_" #fn, &a.fn)
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
}

std::shared_ptr<const Raw1394Library> Raw1394Library::load(const std::string& file) {
  const DlChoice choice = DlLibrary::choose(kSearch, file);
  // one instance per file: every transport and listing of the process, and
  // a test's own handle on its stand-in, see the same library
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<const Raw1394Library>> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  if (auto it = loaded.find(choice.file); it != loaded.end()) {
    if (auto lib = it->second.lock()) return lib;
  }
  // DeviceOpenError naming what was looked for, or the missing symbol
  std::shared_ptr<const Raw1394Library> lib(new Raw1394Library(choice));
  loaded[choice.file] = lib;
  return lib;
}

void* Raw1394Library::symbol(const char* name) const noexcept {
  return dl_.symbol(name);
}

std::string Raw1394Library::describe_search() {
  return DlLibrary::describe_search(kSearch);
}

}  // namespace vmh::hw::fw
