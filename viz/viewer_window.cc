#include "viz/viewer_window.h"

#include <GLFW/glfw3.h>

#include <string>

#include "viz/gl_context.h"

namespace vmh::viz {
namespace {

Viewer* owner_of(GLFWwindow* w) {
  return static_cast<Viewer*>(glfwGetWindowUserPointer(w));
}

void on_key(GLFWwindow* w, int key, int /*scancode*/, int action, int mods) {
  InputEvent e;
  e.type = InputEvent::Type::kKey;
  e.key = key;
  e.press = action != GLFW_RELEASE;
  e.shift = (mods & GLFW_MOD_SHIFT) != 0;
  e.ctrl = (mods & GLFW_MOD_CONTROL) != 0;
  owner_of(w)->inject(e);
}

void on_button(GLFWwindow* w, int button, int action, int mods) {
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(w, &x, &y);
  owner_of(w)->inject(InputEvent::click(button, action == GLFW_PRESS, x, y,
                                         (mods & GLFW_MOD_SHIFT) != 0,
                                         (mods & GLFW_MOD_CONTROL) != 0));
}

void on_move(GLFWwindow* w, double x, double y) {
  InputEvent e = InputEvent::move(x, y);
  e.shift = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
            glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
  owner_of(w)->inject(e);
}

void on_scroll(GLFWwindow* w, double /*dx*/, double dy) {
  InputEvent e;
  e.type = InputEvent::Type::kScroll;
  e.scroll = dy;
  owner_of(w)->inject(e);
}

}  // namespace

Viewer::Window::Window(int width_px, int height_px, const char* title,
                       Viewer* owner) {
  // GLFW is the process's, shared with the renderer (viz/gl_context.h)
  std::string why;
  if (!init_glfw_once(&why)) {
    throw ViewerError("cannot open a window: " + why);
  }
  take_glfw_error();  // only what this window's creation reports
  glfwWindowHint(GLFW_SAMPLES, 0);
  glfw = glfwCreateWindow(width_px, height_px, title, nullptr, nullptr);
  glfwDefaultWindowHints();
  if (glfw == nullptr) {
    throw ViewerError("cannot open a window: " + take_glfw_error());
  }
  glfwMakeContextCurrent(glfw);
  glfwSwapInterval(1);  // at the display's rate, not as fast as possible
  glfwSetWindowUserPointer(glfw, owner);
  glfwSetKeyCallback(glfw, on_key);
  glfwSetMouseButtonCallback(glfw, on_button);
  glfwSetCursorPosCallback(glfw, on_move);
  glfwSetScrollCallback(glfw, on_scroll);
}

Viewer::Window::~Window() {
  if (glfwGetCurrentContext() == glfw) glfwMakeContextCurrent(nullptr);
  glfwDestroyWindow(glfw);
}

bool Viewer::Window::should_close() const {
  return glfwWindowShouldClose(glfw) != 0;
}

void Viewer::Window::framebuffer_size(int* width_px, int* height_px) const {
  glfwGetFramebufferSize(glfw, width_px, height_px);
}

int Viewer::Window::window_height_px() const {
  int w = 0, h = 0;
  glfwGetWindowSize(glfw, &w, &h);
  return h;
}

void Viewer::Window::swap() { glfwSwapBuffers(glfw); }

void Viewer::Window::poll() { glfwPollEvents(); }

}  // namespace vmh::viz
