#include "hw/openhaptics/hd_library.h"

#include <dlfcn.h>

#include <cstdlib>
#include <type_traits>

#include "device/device_backend.h"

namespace vmh::hw::hd {

namespace {

// VMH_LIBHD's value, or empty when it is unset or empty
std::string path_from_environment() {
  const char* v = std::getenv(HdLibrary::kPathVariable);
  return v != nullptr ? std::string(v) : std::string();
}

std::string what_was_looked_for(const std::string& file, bool from_env) {
  if (from_env) return std::string(HdLibrary::kPathVariable) + "=" + file;
  if (file.find('/') != std::string::npos) return file;
  return file +
         " on the loader's search path (LD_LIBRARY_PATH, /etc/ld.so.cache, "
         "/lib, /usr/lib; or set " +
         HdLibrary::kPathVariable + " to its path)";
}

std::string last_dl_error() {
  const char* e = dlerror();
  return e != nullptr ? std::string(e) : std::string("no reason given");
}

}  // namespace

HdLibrary::HdLibrary() : HdLibrary(std::string()) {}

HdLibrary::HdLibrary(const std::string& file_in) {
  bool from_env = false;
  file_ = file_in;
  if (file_.empty()) {
    file_ = path_from_environment();
    from_env = !file_.empty();
    if (!from_env) file_ = kDefaultName;
  }
  // VMH_LIBHD is an exact path: a bare name there means the working
  // directory, not the loader's search
  std::string to_open = file_;
  if (from_env && to_open.find('/') == std::string::npos) to_open = "./" + to_open;

  dlerror();
  handle_ = dlopen(to_open.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle_ == nullptr) {
    throw DeviceOpenError("openhaptics: cannot load " +
                          what_was_looked_for(file_, from_env) + ": " +
                          last_dl_error());
  }

  auto resolve = [&](const char* name, auto* slot) {
    dlerror();
    void* sym = dlsym(handle_, name);
    if (sym == nullptr) {
      const std::string why = last_dl_error();
      dlclose(handle_);
      handle_ = nullptr;
      throw DeviceOpenError("openhaptics: " + file_ + " has no symbol " +
                            name + " (is it the OpenHaptics HD library?): " +
                            why);
    }
    // POSIX guarantees a data pointer from dlsym converts to a function
    // pointer
    *slot = reinterpret_cast<std::remove_pointer_t<decltype(slot)>>(sym);
  };
#define VMH_HD_RESOLVE(fn) resolve(#fn, &api_.fn)
  VMH_HD_RESOLVE(hdInitDevice);
  VMH_HD_RESOLVE(hdDisableDevice);
  VMH_HD_RESOLVE(hdMakeCurrentDevice);
  VMH_HD_RESOLVE(hdBeginFrame);
  VMH_HD_RESOLVE(hdEndFrame);
  VMH_HD_RESOLVE(hdGetError);
  VMH_HD_RESOLVE(hdGetErrorString);
  VMH_HD_RESOLVE(hdEnable);
  VMH_HD_RESOLVE(hdDisable);
  VMH_HD_RESOLVE(hdGetBooleanv);
  VMH_HD_RESOLVE(hdGetIntegerv);
  VMH_HD_RESOLVE(hdGetDoublev);
  VMH_HD_RESOLVE(hdGetLongv);
  VMH_HD_RESOLVE(hdGetString);
  VMH_HD_RESOLVE(hdSetDoublev);
  VMH_HD_RESOLVE(hdCheckCalibration);
  VMH_HD_RESOLVE(hdUpdateCalibration);
  VMH_HD_RESOLVE(hdStartScheduler);
  VMH_HD_RESOLVE(hdStopScheduler);
  VMH_HD_RESOLVE(hdScheduleAsynchronous);
  VMH_HD_RESOLVE(hdScheduleSynchronous);
  VMH_HD_RESOLVE(hdUnschedule);
#undef VMH_HD_RESOLVE
  // the project's extension, where the library is the project's own
  api_.vmhdGetSchedulerTime = reinterpret_cast<PfnVmhdSchedulerTime>(
      dlsym(handle_, "vmhdGetSchedulerTime"));
  api_.vmhdReadTruth =
      reinterpret_cast<PfnVmhdReadTruth>(dlsym(handle_, "vmhdReadTruth"));
  dlerror();
}

HdLibrary::~HdLibrary() {
  if (handle_ != nullptr) dlclose(handle_);
}

std::string HdLibrary::describe_search() {
  const std::string env = path_from_environment();
  if (!env.empty()) return std::string(kPathVariable) + "=" + env;
  return what_was_looked_for(kDefaultName, false);
}

}  // namespace vmh::hw::hd
