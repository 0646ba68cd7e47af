// An OpenGL context for offscreen renders: a hidden GLFW window whose
// context is made current on the calling thread. MuJoCo's renderer
// (mjr_makeContext, mjr_render) needs one; on a machine without a display
// run under Xvfb (`xvfb-run -a`, tests/viz/CMakeLists.txt).
#ifndef VMHAPTICS_VIZ_GL_CONTEXT_H_
#define VMHAPTICS_VIZ_GL_CONTEXT_H_

struct GLFWwindow;

#include <string>

namespace vmh::viz {

// GLFW for the whole process, shared by the renderer's hidden windows and
// the viewer's window: glfwInit once, with one error callback, and never
// glfwTerminate (that would close every other window of the process).
// Returns false with GLFW's own text in *error when there is no display.
bool init_glfw_once(std::string* error);
// the last error GLFW reported since the previous call ("no GLFW error
// text" if none), cleared
std::string take_glfw_error();

class GlContext {
 public:
  // Initialises GLFW (once per process) and opens a hidden window of
  // width x height pixels (its own framebuffer is not drawn to: renders go
  // to MuJoCo's offscreen buffer). Throws std::runtime_error "no OpenGL
  // context: ..." naming the cause, with GLFW's own error text, when there
  // is no display or no usable OpenGL.
  explicit GlContext(int width_px = 64, int height_px = 64);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Makes this context current on the calling thread (the constructor
  // already did for the thread that built it).
  void make_current();
  GLFWwindow* window() const { return window_; }

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_GL_CONTEXT_H_
