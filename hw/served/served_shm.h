// The served device's transport: the shared-memory object
// /dev/shm/vmhaptics-hd-NAME that holds one ServedRegion
// (hw/served/served_region.h), created by the server and mapped by the
// client. Linux; no MuJoCo.
//
// The object is a file in a memory file system: /dev/shm (where glibc's
// shm_open puts its objects), or the directory VMH_SERVED_DIR names, for
// a private set of served devices (the tests, the generated docs) or one
// shared between containers. Both sides must see the same directory.
//
// The server creates the object with mode 0600 (the user's own processes
// only). A name left behind by a server that died (its pid no longer
// runs) is taken over; one whose server still runs is refused, naming the
// pid. The server removes the name when it ends.
#ifndef VMHAPTICS_HW_SERVED_SERVED_SHM_H_
#define VMHAPTICS_HW_SERVED_SERVED_SHM_H_

#include <memory>
#include <string>
#include <vector>

#include "hw/served/served_region.h"

namespace vmh::hw::served {

// VMH_SERVED_DIR if set and not empty, else /dev/shm
std::string served_directory();

// whether a process of that pid runs (kill(pid, 0): EPERM counts as
// running). No allocation.
bool process_alive(int pid) noexcept;

class ShmRegion {
 public:
  // The server's: creates /dev/shm/vmhaptics-hd-NAME, constructs the
  // region in it (magic last) with server_pid = this process. Throws
  // DeviceOpenError naming the name and the cause (a bad name; served
  // already by a running pid; shm_open, ftruncate or mmap's errno text).
  static std::unique_ptr<ShmRegion> create(const std::string& name);
  // The client's: maps an existing one. Throws DeviceOpenError: no such
  // served device (naming the ones there are and how to start one), not a
  // regular file, a region of another build (region_header_error), its
  // server not running.
  static std::unique_ptr<ShmRegion> open(const std::string& name);

  ~ShmRegion();  // unmaps; the server's also removes the name
  ShmRegion(const ShmRegion&) = delete;
  ShmRegion& operator=(const ShmRegion&) = delete;

  ServedRegion* region() noexcept { return region_; }
  const ServedRegion* region() const noexcept { return region_; }
  const std::string& name() const { return name_; }
  bool owner() const { return owner_; }

 private:
  ShmRegion(std::string name, ServedRegion* region, bool owner);
  std::string name_;
  ServedRegion* region_ = nullptr;
  bool owner_ = false;
};

// One name under /dev/shm that looks like a served device.
struct ServedListing {
  std::string name;
  int server_pid = 0;
  bool serving = false;  // its server runs and serves
  int client_pid = 0;    // 0: free
  std::string model;     // the served device's identity, where readable
  std::string serial;
  std::string why_not;   // why it cannot be opened, else ""
};
// The served devices on this machine (none: an empty list). Never throws.
std::vector<ServedListing> list_served();

}  // namespace vmh::hw::served

#endif  // VMHAPTICS_HW_SERVED_SERVED_SHM_H_
