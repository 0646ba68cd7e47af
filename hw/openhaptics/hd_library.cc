#include "hw/openhaptics/hd_library.h"

namespace vmh::hw::hd {

namespace {

const DlSearch kSearch{"openhaptics", HdLibrary::kPathVariable, HdLibrary::kDefaultName,
                       "LD_LIBRARY_PATH, /etc/ld.so.cache, /lib, /usr/lib",
                       "is it the OpenHaptics HD library?"};

}  // namespace

HdLibrary::HdLibrary() : HdLibrary(std::string()) {}

HdLibrary::HdLibrary(const std::string& file) : dl_(kSearch, file) {
#define VMH_HD_RESOLVE(fn) dl_.resolve(#fn, &api_.fn)
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
  api_.vmhdGetSchedulerTime =
      reinterpret_cast<PfnVmhdSchedulerTime>(dl_.symbol("vmhdGetSchedulerTime"));
  api_.vmhdReadTruth = reinterpret_cast<PfnVmhdReadTruth>(dl_.symbol("vmhdReadTruth"));
}

std::string HdLibrary::describe_search() { return DlLibrary::describe_search(kSearch); }

}  // namespace vmh::hw::hd
