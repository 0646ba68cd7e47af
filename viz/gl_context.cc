#include "viz/gl_context.h"

#include <GLFW/glfw3.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace vmh::viz {
namespace {

// GLFW reports its errors through a callback, not a return value: keep the
// last one for the exception's message
std::mutex g_mutex;
std::string g_last_error;

void on_glfw_error(int code, const char* text) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_last_error = "GLFW error " + std::to_string(code) + ": " +
                 (text != nullptr ? text : "(no text)");
}

}  // namespace

std::string take_glfw_error() {
  std::lock_guard<std::mutex> lock(g_mutex);
  std::string e = g_last_error.empty() ? std::string("no GLFW error text")
                                       : g_last_error;
  g_last_error.clear();
  return e;
}

bool init_glfw_once(std::string* error) {
  static std::once_flag once;
  static bool ok = false;
  static std::string init_error;
  std::call_once(once, [] {
    glfwSetErrorCallback(on_glfw_error);
    ok = glfwInit() == GLFW_TRUE;
    if (!ok) init_error = take_glfw_error();
  });
  if (!ok) *error = init_error;
  return ok;
}

namespace {

const char* const kNoContext =
    "no OpenGL context: GLFW could not open a window (no X display? run "
    "under xvfb-run or set DISPLAY)";

}  // namespace

GlContext::GlContext(int width_px, int height_px) {
  std::string error;
  if (!init_glfw_once(&error)) {
    throw std::runtime_error(std::string(kNoContext) + ": " + error);
  }
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  // MuJoCo 2.2 draws with the compatibility profile (fixed-function calls)
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  window_ = glfwCreateWindow(width_px < 1 ? 1 : width_px,
                             height_px < 1 ? 1 : height_px, "vmhaptics render",
                             nullptr, nullptr);
  glfwDefaultWindowHints();
  if (window_ == nullptr) {
    throw std::runtime_error(std::string(kNoContext) + ": " + take_glfw_error());
  }
  glfwMakeContextCurrent(window_);
}

GlContext::~GlContext() {
  if (window_ != nullptr) {
    if (glfwGetCurrentContext() == window_) glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window_);
  }
}

void GlContext::make_current() { glfwMakeContextCurrent(window_); }

}  // namespace vmh::viz
