#include "hw/served/served_shm.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <new>

#include "device/device_backend.h"

namespace vmh::hw::served {
namespace {

std::string errno_text(int e) { return std::strerror(e); }

// the object's file: shm_open's own place (glibc's shm_open opens
// /dev/shm/NAME), or the directory VMH_SERVED_DIR names
std::string object_name(const std::string& name) {
  return served_directory() + kShmPrefix + name;
}

std::string where(const std::string& name) {
  return "served:" + name + " (" + object_name(name) + ")";
}

// opens the object's file without following a link and without blocking
// on a FIFO (checked to be a regular file by the caller)
int open_object(const std::string& name, int flags, mode_t mode = 0) {
  return ::open(object_name(name).c_str(),
                flags | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, mode);
}

// closes a descriptor on every path out
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// maps the object open on fd read-write; nullptr and *error on failure
void* map_object(int fd, std::size_t size, std::string* error) {
  void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) {
    *error = "mmap: " + errno_text(errno);
    return nullptr;
  }
  return p;
}

// the server pid and serving flag of an existing object, if it is a
// region of this build; false otherwise
bool peek_server(const std::string& name, int* pid, bool* serving,
                 std::string* why_not) {
  Fd f;
  f.fd = open_object(name, O_RDONLY);
  if (f.fd < 0) {
    *why_not = "open: " + errno_text(errno);
    return false;
  }
  struct stat st {};
  if (::fstat(f.fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    *why_not = "not a regular shared-memory object";
    return false;
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  if (size < sizeof(ServedRegion)) {
    *why_not = region_header_error(nullptr, size);
    return false;
  }
  void* p = ::mmap(nullptr, sizeof(ServedRegion), PROT_READ, MAP_SHARED, f.fd, 0);
  if (p == MAP_FAILED) {
    *why_not = "mmap: " + errno_text(errno);
    return false;
  }
  *why_not = region_header_error(p, size);
  const auto* r = static_cast<const ServedRegion*>(p);
  if (why_not->empty()) {
    *pid = r->server_pid.load();
    *serving = r->serving.load() != 0 && process_alive(*pid);
  }
  ::munmap(p, sizeof(ServedRegion));
  return why_not->empty();
}

std::vector<std::string> served_names() {
  std::vector<std::string> names;
  DIR* dir = ::opendir(served_directory().c_str());
  if (dir == nullptr) return names;
  const std::string prefix = std::string(kShmPrefix).substr(1);  // no '/' 
  while (const dirent* e = ::readdir(dir)) {
    const std::string n = e->d_name;
    if (n.size() > prefix.size() && n.compare(0, prefix.size(), prefix) == 0) {
      names.push_back(n.substr(prefix.size()));
    }
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

std::string served_directory() {
  const char* dir = std::getenv("VMH_SERVED_DIR");
  return dir != nullptr && dir[0] != '\0' ? std::string(dir) : std::string("/dev/shm");
}

bool process_alive(int pid) noexcept {
  if (pid <= 0) return false;
  return ::kill(pid, 0) == 0 || errno == EPERM;
}

ShmRegion::ShmRegion(std::string name, ServedRegion* region, bool owner)
    : name_(std::move(name)), region_(region), owner_(owner) {}

ShmRegion::~ShmRegion() {
  if (region_ == nullptr) return;
  if (owner_) {
    region_->serving.store(0);
    ::unlink(object_name(name_).c_str());
  }
  ::munmap(region_, sizeof(ServedRegion));
}

std::unique_ptr<ShmRegion> ShmRegion::create(const std::string& name) {
  const std::string bad = served_name_error(name);
  if (!bad.empty()) throw DeviceOpenError("serve: " + bad);
  const std::string obj = object_name(name);
  Fd f;
  for (int attempt = 0; attempt < 2; ++attempt) {
    f.fd = open_object(name, O_CREAT | O_EXCL | O_RDWR, 0600);
    if (f.fd >= 0) break;
    if (errno != EEXIST) {
      throw DeviceOpenError("serve " + where(name) + ": open: " +
                            errno_text(errno));
    }
    int pid = 0;
    bool serving = false;
    std::string why;
    if (peek_server(name, &pid, &serving, &why) && serving) {
      throw DeviceOpenError("serve " + where(name) + ": already served by pid " +
                            std::to_string(pid) + "; choose another name or "
                            "end that server");
    }
    // left behind by a server that is gone (or not ours to read): take over
    if (::unlink(obj.c_str()) != 0 && errno != ENOENT) {
      throw DeviceOpenError("serve " + where(name) + ": a stale object is in "
                            "the way and cannot be removed: " + errno_text(errno));
    }
  }
  if (f.fd < 0) {
    throw DeviceOpenError("serve " + where(name) + ": open: " +
                          errno_text(errno));
  }
  if (::ftruncate(f.fd, static_cast<off_t>(sizeof(ServedRegion))) != 0) {
    const int e = errno;
    ::unlink(obj.c_str());
    throw DeviceOpenError("serve " + where(name) + ": ftruncate: " + errno_text(e));
  }
  std::string error;
  void* p = map_object(f.fd, sizeof(ServedRegion), &error);
  if (p == nullptr) {
    ::unlink(obj.c_str());
    throw DeviceOpenError("serve " + where(name) + ": " + error);
  }
  auto* r = new (p) ServedRegion();
  r->version = kServedVersion;
  r->size = static_cast<std::uint32_t>(sizeof(ServedRegion));
  r->server_pid.store(static_cast<std::int32_t>(::getpid()));
  std::atomic_thread_fence(std::memory_order_release);
  // the magic last: a client that sees it sees a constructed region
  reinterpret_cast<std::atomic<std::uint64_t>*>(&r->magic)
      ->store(kServedMagic, std::memory_order_release);
  return std::unique_ptr<ShmRegion>(new ShmRegion(name, r, true));
}

std::unique_ptr<ShmRegion> ShmRegion::open(const std::string& name) {
  const std::string bad = served_name_error(name);
  if (!bad.empty()) throw DeviceOpenError("--device served:NAME: " + bad);
  Fd f;
  f.fd = open_object(name, O_RDWR);
  if (f.fd < 0) {
    const int e = errno;
    if (e == ENOENT) {
      std::string there;
      for (const std::string& n : served_names()) there += (there.empty() ? "" : ", ") + n;
      throw DeviceOpenError(
          where(name) + ": no such served device (start one with `vmhaptics "
          "view --serve-hd " + name + "`; served now: " +
          (there.empty() ? std::string("none") : there) + ")");
    }
    throw DeviceOpenError(where(name) + ": open: " + errno_text(e) +
                          (e == EACCES ? " (served by another user: the object "
                                         "is mode 0600)" : ""));
  }
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) {
    throw DeviceOpenError(where(name) + ": fstat: " + errno_text(errno));
  }
  if (!S_ISREG(st.st_mode)) {
    throw DeviceOpenError(where(name) + ": not a regular shared-memory object");
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  if (size < sizeof(ServedRegion)) {
    throw DeviceOpenError(where(name) + ": " + region_header_error(nullptr, size) +
                          " (the server is still starting, or another build's)");
  }
  std::string error;
  void* p = map_object(f.fd, sizeof(ServedRegion), &error);
  if (p == nullptr) throw DeviceOpenError(where(name) + ": " + error);
  const std::string header = region_header_error(p, size);
  if (!header.empty()) {
    ::munmap(p, sizeof(ServedRegion));
    throw DeviceOpenError(where(name) + ": " + header);
  }
  auto* r = static_cast<ServedRegion*>(p);
  const int pid = r->server_pid.load();
  if (r->serving.load() == 0 || !process_alive(pid)) {
    ::munmap(p, sizeof(ServedRegion));
    throw DeviceOpenError(where(name) + ": its server (pid " + std::to_string(pid) +
                          ") is not serving; start it again with `vmhaptics "
                          "view --serve-hd " + name + "`");
  }
  return std::unique_ptr<ShmRegion>(new ShmRegion(name, r, false));
}

std::vector<ServedListing> list_served() {
  std::vector<ServedListing> out;
  try {
    for (const std::string& n : served_names()) {
      ServedListing l;
      l.name = n;
      bool serving = false;
      if (peek_server(n, &l.server_pid, &serving, &l.why_not)) {
        l.serving = serving;
        if (!serving) l.why_not = "its server (pid " + std::to_string(l.server_pid) +
                                  ") is not serving";
        try {
          auto r = ShmRegion::open(n);
          l.client_pid = r->region()->client_pid.load();
          l.model = text_of(r->region()->identity.model);
          l.serial = text_of(r->region()->identity.serial);
        } catch (const DeviceOpenError&) {
          // not serving: already said
        }
      }
      out.push_back(std::move(l));
    }
  } catch (...) {
    // a listing never fails: what was found so far
  }
  return out;
}

}  // namespace vmh::hw::served
