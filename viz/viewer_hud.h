// The viewer's text panel and live plots, drawn over the 3-D view with
// MuJoCo's 2-D renderer (mjr_overlay, mjr_figure).
#ifndef VMHAPTICS_VIZ_VIEWER_HUD_H_
#define VMHAPTICS_VIZ_VIEWER_HUD_H_

#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "controller/controller.h"
#include "viz/viewer_physics.h"

namespace vmh::viz {

// The names of the status flags up in `s`, '|'-joined ("ok" for none).
std::string status_text(ControlStatus s);

// What the panel says, one line each.
struct HudText {
  std::string case_name;
  std::string camera;        // the named camera last chosen (key c), or "free"
  std::string hand;          // "script" or "mouse", or the device
  double k_pos_N_per_mm = 0.0;
  double k_ornt_Nmm_per_rad = 0.0;
  double gain_scale = 1.0;
  double force_N = 0.0;
  double path_error_mm = 0.0;
  std::string status;
  double t_sim_s = 0.0;
  double realtime_factor = 0.0;
  double frames_per_s = 0.0;
  bool paused = false;
  bool slow = false;
  // a served emulator (view --serve-hd): a client program is the
  // controller, so the panel shows the hand's force and the client's
  // device instead of the case's gains and path error
  bool served = false;
  double hand_force_N = 0.0;  // served: what the mouse's hand exerts
};

// The top of a plot's axis from zero: the smallest step * intervals >= max,
// with step 1, 2, 2.5 or 5 times a power of ten, so that each of the
// `intervals` grid lines falls on a round number (36.14 becomes 40 with
// steps of 10 on 4 intervals). 1 for a max that is not a positive number.
double round_axis_top(double max, int intervals);

// The key help line (docs/viewer.md lists the same); `served`: the keys
// and the mouse of view --serve-hd.
const char* hud_help_text(bool served = false);

class Hud {
 public:
  Hud();
  ~Hud();
  // the plots' data: samples oldest first, the last kPlotWindow_s of them
  void set_samples(const PlotSample* samples, int n);
  // served: the upper plot is the hand's force (PlotSample::d_path_mm
  // then carries it, N), not the path error
  void set_served(bool served);
  // draws the panel (top left), the help (bottom left, when `help`) and the
  // two plots (right) in `viewport`
  void draw(const mjrRect& viewport, const HudText& text, bool help,
            const mjrContext* con);

 private:
  // mjvFigure holds 100 lines of 1000 points: 0.8 MB each, on the heap
  std::unique_ptr<mjvFigure> error_fig_;
  std::unique_ptr<mjvFigure> force_fig_;
};

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_VIEWER_HUD_H_
