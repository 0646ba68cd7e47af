// hw/openhaptics/hd_library.h: what is loaded (VMH_LIBHD or the loader's
// search), and a one-line error naming the file or the missing symbol.
#include "hw/openhaptics/hd_library.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "device/device_backend.h"

namespace vmh::hw::hd {
namespace {

// sets VMH_LIBHD for one test and restores it after
class EnvGuard {
 public:
  explicit EnvGuard(const char* value) {
    if (const char* old = std::getenv(HdLibrary::kPathVariable)) {
      had_ = true;
      old_ = old;
    }
    if (value != nullptr) {
      setenv(HdLibrary::kPathVariable, value, 1);
    } else {
      unsetenv(HdLibrary::kPathVariable);
    }
  }
  ~EnvGuard() {
    if (had_) setenv(HdLibrary::kPathVariable, old_.c_str(), 1);
    else unsetenv(HdLibrary::kPathVariable);
  }

 private:
  bool had_ = false;
  std::string old_;
};

std::string open_error() {
  try {
    HdLibrary lib;
  } catch (const DeviceOpenError& e) {
    return e.what();
  }
  return "";
}

TEST(HdLibrary, MissingFileNamesThePath) {
  EnvGuard env("/nonexistent/vmh/libHD.so");
  const std::string msg = open_error();
  ASSERT_FALSE(msg.empty()) << "a missing file was loaded";
  EXPECT_NE(msg.find("VMH_LIBHD=/nonexistent/vmh/libHD.so"), std::string::npos)
      << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
}

TEST(HdLibrary, LoadsTheTestLibraryAndResolvesEverySymbol) {
  EnvGuard env(VMH_FAKE_LIBHD);
  HdLibrary lib;
  EXPECT_EQ(lib.file(), VMH_FAKE_LIBHD);
  const HdApi& api = lib.api();
  const void* fns[] = {
      reinterpret_cast<const void*>(api.hdInitDevice),
      reinterpret_cast<const void*>(api.hdDisableDevice),
      reinterpret_cast<const void*>(api.hdMakeCurrentDevice),
      reinterpret_cast<const void*>(api.hdBeginFrame),
      reinterpret_cast<const void*>(api.hdEndFrame),
      reinterpret_cast<const void*>(api.hdGetError),
      reinterpret_cast<const void*>(api.hdGetErrorString),
      reinterpret_cast<const void*>(api.hdEnable),
      reinterpret_cast<const void*>(api.hdDisable),
      reinterpret_cast<const void*>(api.hdGetBooleanv),
      reinterpret_cast<const void*>(api.hdGetIntegerv),
      reinterpret_cast<const void*>(api.hdGetDoublev),
      reinterpret_cast<const void*>(api.hdGetLongv),
      reinterpret_cast<const void*>(api.hdGetString),
      reinterpret_cast<const void*>(api.hdSetDoublev),
      reinterpret_cast<const void*>(api.hdCheckCalibration),
      reinterpret_cast<const void*>(api.hdUpdateCalibration),
      reinterpret_cast<const void*>(api.hdStartScheduler),
      reinterpret_cast<const void*>(api.hdStopScheduler),
      reinterpret_cast<const void*>(api.hdScheduleAsynchronous),
      reinterpret_cast<const void*>(api.hdScheduleSynchronous),
      reinterpret_cast<const void*>(api.hdUnschedule),
  };
  for (const void* f : fns) EXPECT_NE(f, nullptr);
  // the functions answer: a string the test library returns
  const HDstring model = api.hdGetString(kDeviceModelType);
  ASSERT_NE(model, nullptr);
  EXPECT_NE(std::string(model).find("test libHD"), std::string::npos);
  // an error comes back through the struct returned by value
  EXPECT_EQ(api.hdInitDevice("missing"), kInvalidHandle);
  const HDErrorInfo e = api.hdGetError();
  EXPECT_EQ(e.errorCode, kCommConfigError);
  EXPECT_EQ(api.hdGetError().errorCode, kSuccess);
}

TEST(HdLibrary, LibraryWithoutASymbolNamesIt) {
  EnvGuard env(VMH_PARTIAL_LIBHD);
  const std::string msg = open_error();
  ASSERT_FALSE(msg.empty()) << "a library lacking symbols was accepted";
  // it has hdInitDevice, hdDisableDevice and hdMakeCurrentDevice only
  EXPECT_NE(msg.find("has no symbol hdBeginFrame"), std::string::npos) << msg;
  EXPECT_NE(msg.find(VMH_PARTIAL_LIBHD), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

TEST(HdLibrary, BareNameInTheVariableIsNotSearchedFor) {
  // the loader would find a "libc.so.6" on its path; VMH_LIBHD is a path,
  // so this means ./libc.so.6, which is not there
  EnvGuard env("libc.so.6");
  const std::string msg = open_error();
  EXPECT_NE(msg.find("VMH_LIBHD=libc.so.6"), std::string::npos) << msg;
}

TEST(HdLibrary, WithoutTheVariableTheLoaderIsAskedForLibHD) {
  EnvGuard env(nullptr);
  EXPECT_NE(HdLibrary::describe_search().find("libHD.so"), std::string::npos);
  EXPECT_NE(HdLibrary::describe_search().find("LD_LIBRARY_PATH"),
            std::string::npos);
  const std::string msg = open_error();
  if (msg.empty()) GTEST_SKIP() << "this machine has a libHD.so on its path";
  EXPECT_NE(msg.find("libHD.so on the loader's search path"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("VMH_LIBHD"), std::string::npos) << msg;
}

TEST(HdLibrary, DescribeSearchNamesTheVariable) {
  EnvGuard env("/opt/somewhere/libHD.so");
  EXPECT_EQ(HdLibrary::describe_search(), "VMH_LIBHD=/opt/somewhere/libHD.so");
}

TEST(HdLibrary, EmptyVariableMeansTheSearchPath) {
  EnvGuard env("");
  EXPECT_NE(HdLibrary::describe_search().find("libHD.so on the loader"),
            std::string::npos);
}

}  // namespace
}  // namespace vmh::hw::hd
