// Headless renders of a closed-loop run at chosen simulated times: the
// MuJoCo Omni held by the simulated hand (sim/closed_loop.h) with the
// virtual mechanism drawn over it (viz/overlay.h), one PNG per time.
//
// The run is the one `vmhaptics run` makes (same scene, overrides and
// model hook, same ticks), so an image at t shows the state the trace has
// at t. The same request gives byte-identical files on the same machine
// (the physics is deterministic, and so is Mesa's llvmpipe); across GPUs
// or driver versions the pixels may differ.
#ifndef VMHAPTICS_VIZ_RENDER_H_
#define VMHAPTICS_VIZ_RENDER_H_

#include <stdexcept>
#include <string>
#include <vector>

#include "sim/omni_model_edit.h"

namespace vmh::viz {

// Bad input to render(): a time, a size, an unknown camera. The message
// names what was wrong.
class RenderInputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct RenderRequest {
  std::string scene_path;
  std::string name;                    // the case's name, in file names
  std::vector<std::string> overrides;  // name=value, as `run --set`
  // simulated times, s: in [0, the scene's duration_s] (overrides
  // applied), any order
  std::vector<double> times_s;
  int width_px = 640;   // [16, 4096]
  int height_px = 480;  // [16, 4096]
  std::string camera;   // a camera of the model by name; empty: the default
  bool overlays = true;  // the VM, the stylus axis and the force arrow
  bool label = true;     // the text label (case, t, |F|, distance)
  std::string out_dir;   // created if needed
  sim::ModelHook model_hook;  // as ClosedLoop's (e.g. `--model FILE`)
};

struct RenderedImage {
  double t_s = 0.0;        // the time asked for
  double sim_t_s = 0.0;    // the loop's time when drawn: the first tick end
                           // at or after t_s
  std::string path;        // out_dir/<name>_t<ms, 6 digits>ms.png
  int width_px = 0;
  int height_px = 0;
  double force_N = 0.0;    // |F| commanded on the last tick
  double d_path_mm = 0.0;  // the wrist centre's distance to the VM's path
  double render_wall_s = 0.0;  // drawing, reading back and writing the PNG
};

// The file name for time t_s: "<name>_t" + round(1000 t_s) as 6 digits or
// more + "ms.png" (case1 at 2.5 s: "case1_t002500ms.png").
std::string render_file_name(const std::string& name, double t_s);

// Checks the request without running anything: throws RenderInputError
// naming the bad time, size or empty field (and two times falling on the
// same file name).
void validate_render_request(const RenderRequest& req);

// Runs the loop and writes one PNG per time, in increasing time, each
// atomically. Returns them in that order. Throws RenderInputError for bad
// input (before anything is written: a time past the scene's duration_s
// included), sim::SimError for a bad scene or override, std::runtime_error
// for no OpenGL context (viz/gl_context.h) or a file that cannot be
// written, runtime::SignalStop (runtime/stop.h) when a SIGINT or SIGTERM
// came while a StopSignals lives (polled between frames and every few
// thousand ticks; the images already written are left to the caller).
std::vector<RenderedImage> render(const RenderRequest& req);

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_RENDER_H_
