// vmhaptics render <case|scene.xml> --t s1,s2,... --out DIR
//                   [--width W --height H --camera NAME] [--set name=value]
//                   [--no-overlay] [--no-label] [--model FILE]
//
// Runs the case headless and writes one PNG per time (viz/render.h), then
// prints one JSON object naming them (docs/outputs.md, "render"). Needs an
// OpenGL context: a display, or Xvfb (`xvfb-run -a vmhaptics render ...`).
// Exit codes: 0 written; 2 bad usage or bad input, a time past the scene's
// duration_s included (nothing is written); 1 anything else, no OpenGL
// context included; 130 / 143 SIGINT / SIGTERM (nothing written, unless
// the signal came after every image was in place).
//
// The images are drawn into a private folder beside DIR and moved into DIR
// (one rename each) once every one is written: a render stopped or failed
// half-way adds nothing to DIR.
#include <CLI/CLI.hpp>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include "cli/args.h"
#include "device/stop_signal.h"
#include "runtime/json_util.h"
#include "runtime/stop.h"
#include "sim/mujoco_util.h"
#include "thesis/run_case.h"
#include "viz/render.h"

namespace vmh::cli {
namespace {

struct RenderOptions {
  std::string target;
  std::string times;
  std::string out;
  int width_px = 640;
  int height_px = 480;
  std::string camera;
  std::vector<std::string> sets;
  bool no_overlay = false;
  bool no_label = false;
  std::string model;
};

std::vector<double> parse_times(const std::string& text) {
  std::vector<double> times;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(
        start, comma == std::string::npos ? std::string::npos : comma - start);
    const double t = parse_number("--t", item);
    if (t < 0.0) {
      throw UsageError("--t: time '" + item + "' is negative (want s >= 0)");
    }
    times.push_back(t);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return times;
}

namespace fs = std::filesystem;

// A private folder beside `dir` (".<name>.render-<pid>-XXXXXX", on the same
// file system, so that its files can be renamed into `dir`), removed with
// what is left in it when this goes.
class RenderScratch {
 public:
  explicit RenderScratch(const std::string& dir) {
    fs::path d = fs::path(dir).lexically_normal();
    if (!d.has_filename() && d.has_parent_path()) d = d.parent_path();
    const fs::path parent = d.has_parent_path() ? d.parent_path() : fs::path(".");
    std::error_code ec;
    fs::create_directories(parent, ec);
    std::string templ = (parent / ("." + d.filename().string() + ".render-" +
                                   std::to_string(static_cast<long>(getpid())) +
                                   "-XXXXXX"))
                            .string();
    if (ec || mkdtemp(templ.data()) == nullptr) {
      throw std::runtime_error("render: cannot create a folder beside '" + dir +
                               "'" + (ec ? ": " + ec.message() : ""));
    }
    path_ = templ;
  }
  ~RenderScratch() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  RenderScratch(const RenderScratch&) = delete;
  RenderScratch& operator=(const RenderScratch&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// the request from the options, checked before anything runs
viz::RenderRequest render_request(const RenderOptions& o) {
  viz::RenderRequest req;
  req.times_s = parse_times(o.times);
  try {
    req.scene_path = sim::resolve_scene(o.target, &req.name);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("render: ") + e.what());
  }
  if (!o.model.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(o.model, ec)) {
      throw UsageError("--model: no such file '" + o.model + "'");
    }
    req.model_hook = sim::omni_model_hook(
        std::filesystem::absolute(o.model, ec).string());
  }
  req.overrides = o.sets;
  req.width_px = o.width_px;
  req.height_px = o.height_px;
  req.camera = o.camera;
  req.overlays = !o.no_overlay;
  req.label = !o.no_label;
  req.out_dir = o.out;
  try {
    viz::validate_render_request(req);
  } catch (const viz::RenderInputError& e) {
    throw UsageError(e.what());
  }
  return req;
}

// the images drawn into req's folder; bad input (a time past the scene's
// end, a camera it lacks, a bad scene) is a UsageError, a signal a
// SignalStop with nothing written
std::vector<viz::RenderedImage> render_images(const viz::RenderRequest& req) {
  try {
    return viz::render(req);
  } catch (const viz::RenderInputError& e) {
    throw UsageError(e.what());
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("render ") + req.name + ": " + e.what());
  } catch (const runtime::SignalStop&) {
    runtime::throw_if_stopped("render", "; nothing written");
    throw;
  }
}

// each image renamed from the private folder into `out` (created if
// needed), its path then the one in `out`
void move_images(const std::string& out,
                 std::vector<viz::RenderedImage>* images) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) {
    throw std::runtime_error("render: cannot create folder '" + out +
                             "': " + ec.message());
  }
  for (viz::RenderedImage& img : *images) {
    const fs::path to = fs::path(out) / fs::path(img.path).filename();
    fs::rename(img.path, to, ec);
    if (ec) {
      throw std::runtime_error("render: " + to.string() + ": " + ec.message());
    }
    img.path = to.string();
  }
}

// the JSON printed: the request and each image (docs/outputs.md, "render")
Json render_json(const viz::RenderRequest& req,
                 const std::vector<viz::RenderedImage>& images) {
  Json j;
  j["scene"] = req.scene_path;
  j["case"] = req.name;
  j["width_px"] = req.width_px;
  j["height_px"] = req.height_px;
  j["camera"] = req.camera.empty() ? "default" : req.camera;
  j["overlay"] = req.overlays;
  j["images"] = Json::array();
  for (const viz::RenderedImage& img : images) {
    Json im;
    im["t_s"] = img.t_s;
    im["sim_t_s"] = img.sim_t_s;
    im["path"] = img.path;
    im["force_N"] = img.force_N;
    im["d_path_mm"] = img.d_path_mm;
    j["images"].push_back(std::move(im));
  }
  return j;
}

void render_verb(const RenderOptions& o) {
  // SIGINT / SIGTERM only set a flag (device/stop_signal.h), polled
  // between frames (viz::render) and before the images are moved in
  StopSignals signals;
  viz::RenderRequest req = render_request(o);
  std::vector<viz::RenderedImage> images;
  {
    RenderScratch scratch(o.out);
    req.out_dir = scratch.path();
    images = render_images(req);
    runtime::throw_if_stopped("render", "; nothing written");
    move_images(o.out, &images);
  }
  // a signal while the images went in: they are all there, and the exit
  // says so
  runtime::throw_if_stopped("render", "; its images were already in " + o.out);
  std::cout << dump_readable(render_json(req, images)) << '\n';
}

}  // namespace

void register_render(CLI::App* app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app->add_subcommand(
      "render",
      "headless PNG renders of a case (case1..case7) or a scene file "
      "at given simulated times: the MuJoCo Omni held by the simulated hand, "
      "with the virtual mechanism, the stylus axis and the commanded force "
      "drawn over it; needs a display or Xvfb (xvfb-run -a vmhaptics "
      "render ...); prints one JSON object naming the files");
  cmd->add_option("target", o->target,
                  "case1..case7, or the path of a scene .xml")
      ->required();
  cmd->add_option("--t", o->times,
                  "simulated times in s, comma-separated (e.g. 0.5,1,2.5); "
                  "each in [0, the scene's duration_s]; each image shows the "
                  "first servo tick ending at or after its time")
      ->required();
  cmd->add_option("--out", o->out,
                  "folder for the images, created if needed: "
                  "DIR/<case>_t<time in ms, 6 digits>ms.png")
      ->required();
  cmd->add_option("--width", o->width_px,
                  "image width in px, 16..4096 (default 640)");
  cmd->add_option("--height", o->height_px,
                  "image height in px, 16..4096 (default 480)");
  cmd->add_option("--camera", o->camera,
                  "a camera of the model, by name (default: a free camera "
                  "framing the arm and the VM's path from the user's side)");
  cmd->add_option("--set", o->sets,
                  "override a case parameter, name=value, as for run; "
                  "repeatable")
      ->allow_extra_args(false);
  cmd->add_flag("--no-overlay", o->no_overlay,
                "the MuJoCo scene only: no VM path, links, stylus axis or "
                "force arrow");
  cmd->add_flag("--no-label", o->no_label,
                "no text label (case, t, |F|, distance to the path)");
  cmd->add_option("--model", o->model,
                  "a calibrated Omni MJCF whose parameters replace the "
                  "scene's Omni's, as for run");
  cmd->callback([o] { render_verb(*o); });
}

}  // namespace vmh::cli
