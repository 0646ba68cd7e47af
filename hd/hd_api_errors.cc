// The open HD API's errors (include/HD/hdDefines.h's codes): a fixed stack
// per thread, the most recent on top, which the servo thread pushes onto
// without allocating; the cause of each code's last failure, kept for
// hdGetErrorString. docs/libhd.md is the account of each code's meaning
// here.
#define VMHAPTICS_HD_BUILDING 1
#include <HD/hd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

#include "hd/hd_api_detail.h"

namespace vmh::hd::detail {
namespace {

constexpr int kErrorDepth = 32;

// -- errors: a stack per thread, the most recent on top --
struct ErrorStack {
  HDErrorInfo e[kErrorDepth];
  int n = 0;
};
thread_local ErrorStack t_errors;

// the cause of the last failure of each code (hdGetErrorString), written
// only off the servo thread
std::mutex g_detail_mu;
std::string g_detail[8];  // index: kind below
int detail_slot(HDerror code) {
  switch (code) {
    case HD_COMM_CONFIG_ERROR: return 0;
    case HD_COMM_ERROR: return 1;
    case HD_DEVICE_FAULT: return 2;
    case HD_TIMER_ERROR: return 3;
    case HD_DEVICE_ALREADY_INITIATED: return 4;
    case HD_INVALID_VALUE: return 5;
    case HD_INVALID_OPERATION: return 6;
    default: return -1;
  }
}

const char* base_text(HDerror code) {
  switch (code) {
    case HD_SUCCESS: return "no error";
    case HD_INVALID_ENUM: return "invalid parameter name";
    case HD_INVALID_VALUE: return "invalid value";
    case HD_INVALID_OPERATION: return "invalid operation";
    case HD_INVALID_INPUT_TYPE: return "the parameter cannot be read or set as this type";
    case HD_BAD_HANDLE: return "no device has that handle";
    case HD_WARM_MOTORS: return "the motors are warm: the force is derated";
    case HD_EXCEEDED_MAX_FORCE: return "the force asked for exceeded the maximum";
    case HD_EXCEEDED_MAX_FORCE_IMPULSE: return "the force changed faster than the impulse limit allows";
    case HD_EXCEEDED_MAX_VELOCITY: return "the device moved faster than the velocity limit: force cut";
    case HD_FORCE_ERROR: return "force error";
    case HD_DEVICE_FAULT: return "device fault";
    case HD_DEVICE_ALREADY_INITIATED: return "the device is already initialised";
    case HD_COMM_ERROR: return "communication with the device failed";
    case HD_COMM_CONFIG_ERROR: return "the device could not be opened";
    case HD_TIMER_ERROR: return "the servo loop could not be started";
    case HD_ILLEGAL_BEGIN: return "hdBeginFrame in a frame of that device";
    case HD_ILLEGAL_END: return "hdEndFrame without hdBeginFrame";
    case HD_FRAME_ERROR: return "a state call outside the frame it needs";
    case HD_INVALID_PRIORITY: return "invalid scheduler priority";
    case HD_SCHEDULER_FULL: return "the scheduler has no room for another callback";
    case HD_INVALID_LICENSE: return "licence error (never raised here)";
    default: return "unknown HD error code";
  }
}

}  // namespace

void push_error(HDerror code, int internal, HHD h) noexcept {
  ErrorStack& s = t_errors;
  if (s.n == kErrorDepth) {  // the oldest is dropped
    std::memmove(&s.e[0], &s.e[1], sizeof(HDErrorInfo) * (kErrorDepth - 1));
    --s.n;
  }
  s.e[s.n++] = HDErrorInfo{code, internal, h};
}

void set_detail(HDerror code, const std::string& text) {
  const int i = detail_slot(code);
  if (i < 0) return;
  std::lock_guard<std::mutex> lock(g_detail_mu);
  g_detail[i] = text;
  if (std::getenv("VMH_HD_QUIET") == nullptr) {
    std::fprintf(stderr, "vmhaptics libHD: %s\n", text.c_str());
  }
}

}  // namespace vmh::hd::detail

using namespace vmh::hd::detail;  // NOLINT: this file implements the C API

// ---- errors ----

HDAPI HDErrorInfo HDAPIENTRY hdGetError(void) {
  ErrorStack& s = t_errors;
  if (s.n == 0) return HDErrorInfo{HD_SUCCESS, 0, current_handle()};
  return s.e[--s.n];
}

HDAPI HDstring HDAPIENTRY hdGetErrorString(HDerror code) {
  const int i = detail_slot(code);
  if (i >= 0 && !on_servo_thread()) {
    // "<what the code means>: <the last cause>", kept until the next one
    static thread_local std::string out;
    std::lock_guard<std::mutex> lock(g_detail_mu);
    if (!g_detail[i].empty()) {
      out = std::string(base_text(code)) + ": " + g_detail[i];
      return out.c_str();
    }
  }
  return base_text(code);
}
