// The viewer's GLFW window: opening it (with GLFW's own error text when
// that fails, e.g. no display) and turning GLFW's callbacks into
// InputEvents for Viewer::inject.
#ifndef VMHAPTICS_VIZ_VIEWER_WINDOW_H_
#define VMHAPTICS_VIZ_VIEWER_WINDOW_H_

#include "viz/viewer.h"

struct GLFWwindow;

namespace vmh::viz {

struct Viewer::Window {
  // Throws ViewerError naming GLFW's reason.
  Window(int width_px, int height_px, const char* title, Viewer* owner);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  bool should_close() const;
  void framebuffer_size(int* width_px, int* height_px) const;
  int window_height_px() const;
  void swap();
  static void poll();

  GLFWwindow* glfw = nullptr;
};

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_VIEWER_WINDOW_H_
