// vmhaptics view <case1..case6|scene.xml> [--device D] [--frames N]
//                [--set name=value ...] [--out DIR] [--mouse]
// vmhaptics view [case|scene.xml] --serve-hd NAME [--frames N] ...
//
// An interactive window (viz/viewer.h, docs/viewer.md): the case's Omni in
// MuJoCo's renderer, simulated in real time, with the mouse able to take
// the simulated hand's place; or, with --device, a device's live state.
// Exit codes: 0 closed, 2 bad usage or input (an unknown case, a bad
// --set, a device that cannot be opened, a served name that is taken),
// 1 any other failure (no display:
// GLFW's reason is in the message).
#include <CLI/CLI.hpp>

#include <filesystem>
#include <memory>

#include "cli/args.h"
#include "device/stop_signal.h"
#include "runtime/backend_registry.h"
#include "runtime/session.h"
#include "runtime/trace_writer.h"
#include "controller/device_frame.h"
#include "sim/closed_loop.h"
#include "sim/served_emulator.h"
#include "thesis/run_case.h"
#include "viz/viewer.h"

namespace vmh::cli {
namespace {

struct ViewOptions {
  std::string target;
  std::string device;  // empty: the viewer's own simulation
  std::string serve_hd;  // serve the emulator as served:NAME
  int frames = 0;
  std::vector<std::string> sets;
  std::string out = ".";
  bool mouse = false;
  bool screenshot = false;
  int width_px = 1280;
  int height_px = 800;
};

// the device's servo loop running the case's controller on the wall clock
// (a person watches), watched by the viewer through the session's latest
// record (a Seqlock: the loop never waits)
struct LiveDevice {
  runtime::OpenedDevice dev;
  std::unique_ptr<runtime::LiveSession> session;
  ~LiveDevice() {
    if (session) session->stop();  // zero torque at the device
  }
};

std::unique_ptr<LiveDevice> open_live(const ViewOptions& o,
                                      const std::string& scene,
                                      viz::ViewerOptions* vo) {
  const runtime::BackendRegistry& reg = runtime::BackendRegistry::global();
  std::string argument;
  const runtime::BackendInfo& backend = reg.resolve(o.device, &argument);
  if (backend.simulated && !argument.empty()) {
    throw UsageError("view: the emulator plays the viewed scene; give it "
                     "as the target, not in --device (" + o.device + ")");
  }
  // the case's controller, as hw run builds it
  ControllerParams params;
  try {
    params = sim::load_case(scene, o.sets).controller_params();
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("view: ") + e.what());
  }
  auto live = std::make_unique<LiveDevice>();
  runtime::OpenRequest rq;
  rq.defaults["hand"] = "case";
  rq.scene_sets = o.sets;
  live->dev = reg.open(backend.simulated ? backend.name + ":" + scene : o.device,
                       rq);
  ChainOptions chain;
  chain.mode = ChainMode::kRun;
  chain.controller = params;
  chain.safety_params = safety_params_for(params);
  chain.guard.max_period_s = 4.0 * params.servo_period_s;
  ServoOptions servo;
  servo.period_s = params.servo_period_s;
  servo.realtime = false;
  live->session =
      std::make_unique<runtime::LiveSession>(&live->dev, chain, servo);
  runtime::LiveSession* session = live->session.get();
  vo->live = [session] {
    const TickRecord s = session->latest();
    viz::LiveSample out;
    out.valid = session->ticks() > 0 && s.state.present != 0;
    out.t_s = s.t_s;
    out.q_device_rad = s.state.q_device_rad;
    out.out = s.out;
    out.status = "safety " + runtime::safety_flags_text(s.safety);
    return out;
  };
  vo->live_name = o.device;
  return live;
}

// the options that need no scene: a target (case1 by default with
// --serve-hd), --frames, the window's size
void check_view_options(ViewOptions* o) {
  if (o->target.empty()) {
    if (o->serve_hd.empty()) throw UsageError("view: give a case or a scene (target)");
    o->target = "case1";
  }
  if (o->frames < 0) throw UsageError("--frames: must be >= 0");
  if (o->width_px < 64 || o->height_px < 64) {
    throw UsageError("--width, --height: each must be at least 64 px");
  }
}

// the viewed case's name and scene file
struct ViewedScene {
  std::string name;
  std::string scene;
};

ViewedScene resolve_viewed(const std::string& target) {
  ViewedScene v;
  try {
    v.scene = sim::resolve_scene(target, &v.name);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("view: ") + e.what());
  }
  return v;
}

// The viewer's options from the command line's: the cases to step through
// with [ and ] (the thesis's, the viewed one first shown; a scene file
// alone), the overrides, frames, screenshots and window size
viz::ViewerOptions viewer_options(const ViewOptions& o, const ViewedScene& v) {
  viz::ViewerOptions vo;
  for (const sim::CaseEntry& c : sim::case_catalogue()) {
    std::string n;
    vo.cases.push_back({c.name, sim::resolve_scene(c.name, &n)});
    if (n == v.name) vo.case_index = static_cast<int>(vo.cases.size()) - 1;
  }
  if (vo.cases[static_cast<std::size_t>(vo.case_index)].name != v.name) {
    vo.cases = {{v.name, v.scene}};
    vo.case_index = 0;
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(o.out, ec)) {
    throw UsageError("--out: no such directory '" + o.out + "'");
  }
  vo.overrides = o.sets;
  vo.max_frames = o.frames;
  vo.out_dir = o.out;
  vo.start_with_mouse_hand = o.mouse;
  if (o.screenshot && o.frames == 0) {
    throw UsageError("--screenshot: needs --frames N (the last frame's)");
  }
  vo.screenshot_last_frame = o.screenshot;
  vo.width_px = o.width_px;
  vo.height_px = o.height_px;
  return vo;
}

// --serve-hd: the emulator served as served:NAME and started, the one case
// shown, and how to run a program on it said on stderr
std::unique_ptr<sim::ServedEmulator> serve_emulator(const ViewOptions& o,
                                                    const ViewedScene& v,
                                                    viz::ViewerOptions* vo) {
  if (!o.device.empty() || o.mouse) {
    throw UsageError("--serve-hd: the served emulator is driven by a client "
                     "program and held by the mouse; not with --device or "
                     "--mouse");
  }
  sim::ServedEmulatorOptions so;
  so.name = o.serve_hd;
  so.scene = v.scene;
  so.overrides = o.sets;
  std::unique_ptr<sim::ServedEmulator> served;
  try {
    served = std::make_unique<sim::ServedEmulator>(so);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("view: ") + e.what());
  }
  served->start();
  vo->cases = {{v.name, v.scene}};
  vo->case_index = 0;
  vo->served = served.get();
  std::fprintf(stderr,
               "vmhaptics view: serving the emulated Omni of %s as %s; run "
               "an OpenHaptics program on it with\n"
               "  VMH_HD_DEVICE=%s LD_LIBRARY_PATH=<build>/lib program\n"
               "(left-drag grabs the stylus, release lets go)\n",
               v.name.c_str(), served->spec().c_str(), served->spec().c_str());
  return served;
}

// the window until it closes (or its frames are done), then its frame
// rate on stderr; no display is a failure, a bad scene bad input
void run_viewer(const viz::ViewerOptions& vo) {
  std::unique_ptr<viz::Viewer> viewer;
  try {
    viewer = std::make_unique<viz::Viewer>(vo);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("view: ") + e.what());
  } catch (const viz::ViewerError& e) {
    throw std::runtime_error(std::string("view: ") + e.what());
  }
  viewer->run();
  std::fprintf(stderr,
               "vmhaptics view: %ld frames, %.1f frames/s, real-time factor "
               "%.2f\n",
               viewer->frames(), viewer->frames_per_s(),
               viewer->realtime_factor());
}

void view(ViewOptions o) {
  check_view_options(&o);
  const ViewedScene v = resolve_viewed(o.target);
  viz::ViewerOptions vo = viewer_options(o, v);
  // Ctrl-C and kill end the window's loop like its close button, so that
  // a device is left at zero torque and a served name is removed
  StopSignals signals;
  vo.stop_requested = [&signals] { return signals.requested(); };
  std::unique_ptr<LiveDevice> live;
  std::unique_ptr<sim::ServedEmulator> served;
  if (!o.serve_hd.empty()) {
    served = serve_emulator(o, v, &vo);
  } else if (!o.device.empty()) {
    live = open_live(o, v.scene, &vo);
  } else {
    // bad --set values are usage errors even where no window can open
    try {
      (void)sim::load_case(v.scene, o.sets);
    } catch (const sim::SimError& e) {
      throw UsageError(std::string("view: ") + e.what());
    }
  }
  run_viewer(vo);
}

}  // namespace

void register_view(CLI::App* app) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* cmd = app->add_subcommand(
      "view",
      "interactive window: the case's Omni in MuJoCo's renderer, simulated "
      "in real time (1 kHz servo), the virtual mechanism drawn over it, "
      "live plots of the path error and |F|; the mouse can take the "
      "simulated hand's place (key m). Keys: space pause, right arrow one "
      "servo tick, s slow motion x1/4, r reset, [ ] previous/next case, "
      "+ - gains x2 /2, m mouse/scripted hand, o overlay, p screenshot, "
      "h help, esc quit. Mouse hand: left-drag moves the hand's target in "
      "the view plane, shift+left-drag turns it; right-drag turns the "
      "camera, middle-drag pans, scroll zooms. docs/viewer.md");
  cmd->add_option("target", o->target,
                  "case1..case6, or the path of a scene .xml (with "
                  "--serve-hd: whose Omni and hand; default case1)");
  cmd->add_option("--serve-hd", o->serve_hd,
                  "serve the emulated Omni to other programs as the device "
                  "served:NAME (an OpenHaptics program on the project's "
                  "libHD.so with VMH_HD_DEVICE=served:NAME, or hw verbs with "
                  "--device served:NAME) and show it here; nobody holds the "
                  "stylus until a left-drag grabs it (the mouse is the hand), "
                  "release lets go. docs/libhd.md");
  cmd->add_option("--device", o->device,
                  "show a device's live state instead of simulating: "
                  "emulator (plays the target scene) or a backend as in the "
                  "hw verbs (openhaptics[:CONFIG]); the case's controller "
                  "drives it through the safety layer");
  cmd->add_option("--frames", o->frames,
                  "exit after N frames (0: when the window is closed)");
  cmd->add_option("--set", o->sets,
                  "override a case parameter, name=value (vectors "
                  "comma-separated); repeatable. docs/parameters.md lists the "
                  "names")
      ->allow_extra_args(false);
  cmd->add_option("--out", o->out,
                  "directory for screenshots (key p; default: the current "
                  "one), named vmhaptics-view-<case>-<local time>.png");
  cmd->add_flag("--mouse", o->mouse,
                "start with the mouse hand instead of the case's script");
  cmd->add_flag("--screenshot", o->screenshot,
                "with --frames N: write a screenshot of the last frame to "
                "--out before exiting");
  cmd->add_option("--width", o->width_px, "window width in px (1280)");
  cmd->add_option("--height", o->height_px, "window height in px (800)");
  cmd->callback([o] { view(*o); });
}

}  // namespace vmh::cli
