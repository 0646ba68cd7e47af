// The interactive viewer (`vmhaptics view`, docs/viewer.md): the MuJoCo
// Omni of a case in a GLFW window, the overlay of viz/overlay.h over it,
// live plots and a text panel, and the mouse in the simulated hand's place.
//
// Threads. The physics thread (viz/viewer_physics.h) runs ClosedLoop::tick
// at the servo period in real time, whatever the frame rate. The render
// thread (the one that built the Viewer and calls frame()) copies what a
// frame needs from it under a short lock (mj_copyData, the last TickRecord,
// the plot samples) and draws from its copy. With a live device source
// (ViewerOptions::live) there is no physics thread: the scene's model is
// posed from the device's joint readings and the overlay drawn from the
// controller output that came with them.
//
// Input. GLFW's callbacks and a test's synthetic events go through the same
// Viewer::inject(), so what a test drives is what a user drives.
#ifndef VMHAPTICS_VIZ_VIEWER_H_
#define VMHAPTICS_VIZ_VIEWER_H_

#include <array>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "controller/controller.h"
#include "viz/overlay.h"

namespace vmh::sim {
class ServedEmulator;
}

namespace vmh::viz {

// A window cannot be opened (no display, no OpenGL): the message carries
// GLFW's own text.
class ViewerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A case the viewer can show and step to ([ and ] keys).
struct ViewerCase {
  std::string name;   // "case1", or the scene file's stem
  std::string scene;  // the scene file
};

// One reading of a live device, as its servo loop last saw it.
struct LiveSample {
  bool valid = false;        // false until the device's first tick
  double t_s = 0.0;          // since the device loop's first tick
  Joints q_device_rad = Joints::Zero();  // the reading, device convention
  ControlOutput out;         // the controller's output for that reading
  std::string status;        // e.g. the safety layer's flags
};

struct ViewerOptions {
  std::vector<ViewerCase> cases;  // at least one
  int case_index = 0;             // the one shown first
  std::vector<std::string> overrides;  // --set name=value, every case
  int width_px = 1280;
  int height_px = 800;
  int max_frames = 0;             // > 0: run() returns after this many
  std::string out_dir = ".";      // screenshots
  bool start_with_mouse_hand = false;
  bool screenshot_last_frame = false;  // with max_frames: the last one
  // a live device instead of the physics thread (--device); called once a
  // frame from the render thread; must not block
  std::function<LiveSample()> live;
  std::string live_name;          // shown in the text panel
  // an emulator served to another process (`view --serve-hd`,
  // sim/served_emulator.h): shown from its physics, the mouse its hand
  // (left-drag grabs the stylus and moves it, release lets go). Not owned;
  // started by the caller. The case list is then that one scene.
  sim::ServedEmulator* served = nullptr;
  // polled once a frame: true ends run() as closing the window does (the
  // command line's SIGINT / SIGTERM, device/stop_signal.h)
  std::function<bool()> stop_requested;
};

// An input event, in window coordinates (pixels, y down). Keys are GLFW key
// codes (GLFW_KEY_*), buttons GLFW mouse buttons, so that the callbacks
// forward them unchanged.
struct InputEvent {
  enum class Type { kKey, kButton, kMove, kScroll };
  Type type = Type::kMove;
  int key = 0;            // kKey
  int button = 0;         // kButton
  bool press = true;      // kKey, kButton: pressed (or repeated) / released
  bool shift = false;     // modifiers held
  bool ctrl = false;
  double x_px = 0.0;      // kMove: the cursor; kButton: where (if known)
  double y_px = 0.0;
  double scroll = 0.0;    // kScroll: wheel steps, positive away from user

  static InputEvent key_press(int key, bool shift = false);
  static InputEvent click(int button, bool press, double x_px, double y_px,
                           bool shift = false, bool ctrl = false);
  static InputEvent move(double x_px, double y_px);
};

class SimThread;
class Hud;
struct PlotSample;

class Viewer {
 public:
  // Opens the window, builds the first case and starts its physics. Throws
  // ViewerError when no window can be had (GLFW's reason in the message),
  // sim::SimError for a bad scene or override.
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // One frame: events, copy from the physics, render, swap. false once the
  // window was asked to close (Esc, Q, the window's close button).
  bool frame();
  // frames until closed or max_frames; returns the frames drawn
  long run();

  // what a GLFW callback does with an event; a test feeds its own
  void inject(const InputEvent& e);

  // --- state, for the text panel and for tests (render thread) ---
  const std::string& case_name() const;
  double sim_time_s() const { return t_sim_s_; }
  bool paused() const;
  bool slow_motion() const { return slow_; }
  bool mouse_hand() const { return mouse_hand_; }
  double gain_scale() const { return gain_scale_; }
  bool overlay_on() const { return overlay_on_; }
  // the overlay primitives drawn in the last frame (empty with it off)
  const std::vector<OverlayPrimitive>& last_overlay() const { return prims_; }
  // the controller's output shown in the last frame
  const ControlOutput& last_output() const { return out_; }
  // the render thread's copy of the model's state in the last frame
  const mjModel* model() const;
  const mjData* frame_data() const { return d_render_; }
  const mjvCamera& camera() const { return cam_; }
  // the model's camera the view was last set to (key c), "" for none
  const std::string& camera_name() const { return camera_name_; }
  int viewport_width_px() const { return width_px_; }
  int viewport_height_px() const { return height_px_; }
  long frames() const { return frames_; }
  // frames per wall second and simulated per wall second, each over the
  // last second or so
  double frames_per_s() const { return fps_; }
  double realtime_factor() const { return rtf_; }
  // the last screenshot written ("" before the first)
  const std::string& last_screenshot() const { return last_shot_; }

 private:
  void open_window();
  void build_case();          // (re)builds the loop of cases_[case_index_]
  // build_case for another case or gain scale; on failure, back as it was
  void rebuild_or_keep(int case_index, double gain_scale);
  void copy_from_physics();
  void render();
  void screenshot();
  void handle_key(const InputEvent& e);
  void handle_button(const InputEvent& e);
  void handle_move(const InputEvent& e);
  void update_rates();
  void copy_from_served();
  void record_live_plot(double t_s);

  ViewerOptions opt_;
  int case_index_ = 0;
  double gain_scale_ = 1.0;
  bool slow_ = false;
  bool mouse_hand_ = false;
  bool overlay_on_ = true;
  bool help_on_ = true;
  bool want_shot_ = false;
  bool want_close_ = false;

  // the window and MuJoCo's visualisation state (render thread only)
  struct Window;
  std::unique_ptr<Window> win_;
  int width_px_ = 0, height_px_ = 0;  // the framebuffer
  int win_height_px_ = 0;             // the window, for mouse drags
  mjvCamera cam_;
  std::string camera_name_;
  void set_named_camera(int step);  // the next (+1) of the model's cameras
  mjvOption vopt_;
  mjvScene scn_;
  mjrContext con_;
  bool scene_made_ = false;

  // the physics, and the render thread's copy of it
  std::unique_ptr<SimThread> sim_;
  mjData* d_render_ = nullptr;
  // qpos address of the model's joints q1..q6 (-1 where missing), for
  // posing it from a live device's reading
  std::array<int, 6> qpos_adr_{-1, -1, -1, -1, -1, -1};
  std::unique_ptr<Controller> overlay_controller_;  // its mechanism, drawn
  ControlOutput out_;
  double t_sim_s_ = 0.0;
  double d_path_mm_ = 0.0;
  double hand_force_N_ = 0.0;  // served: the hand's force, N
  std::string status_;
  bool have_output_ = false;  // out_ is a controller's, not the default
  std::vector<OverlayPrimitive> prims_;
  std::unique_ptr<Hud> hud_;
  std::unique_ptr<std::array<PlotSample, 1000>> plots_;  // kPlotSamples
  int live_plot_n_ = 0;  // samples in plots_ from a live device

  // the mouse
  bool left_down_ = false, right_down_ = false, middle_down_ = false;
  bool drag_rotate_ = false;
  double last_x_px_ = 0.0, last_y_px_ = 0.0;

  // rates
  long frames_ = 0;
  double fps_ = 0.0, rtf_ = 0.0;
  double rate_wall0_s_ = -1.0, rate_sim0_s_ = 0.0;
  long rate_frames0_ = 0;
  std::string last_shot_;
};

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_VIEWER_H_
