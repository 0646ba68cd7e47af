#include "viz/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "device/stop_signal.h"
#include "runtime/stop.h"
#include "sim/closed_loop.h"
#include "viz/gl_context.h"
#include "viz/overlay.h"
#include "viz/png.h"
#include "viz/scene_renderer.h"

namespace vmh::viz {
namespace {

long time_ms(double t_s) { return std::lround(t_s * 1000.0); }

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

void check_size(const char* what, int px) {
  if (px < 16 || px > 4096) {
    throw RenderInputError(std::string(what) + ": " + std::to_string(px) +
                           " px is outside [16, 4096]");
  }
}

}  // namespace

std::string render_file_name(const std::string& name, double t_s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_t%06ldms.png", time_ms(t_s));
  return name + buf;
}

void validate_render_request(const RenderRequest& req) {
  if (req.scene_path.empty()) throw RenderInputError("render: no scene");
  if (req.name.empty() || req.name.find('/') != std::string::npos) {
    throw RenderInputError("render: bad case name '" + req.name +
                           "' (used in file names)");
  }
  if (req.out_dir.empty()) throw RenderInputError("render: no --out folder");
  if (req.times_s.empty()) throw RenderInputError("--t: no times given");
  for (double t : req.times_s) {
    // an upper bound keeps the tick count (and the ms in names) in range
    if (!std::isfinite(t) || t < 0.0 || t > 1e6) {
      throw RenderInputError("--t: time " + format("%g", t) +
                             " s is not a finite time in [0, 1e6] s");
    }
  }
  std::vector<double> sorted = req.times_s;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    if (time_ms(sorted[i]) == time_ms(sorted[i - 1])) {
      throw RenderInputError("--t: times " + format("%g", sorted[i - 1]) +
                             " and " + format("%g", sorted[i]) +
                             " s fall on the same millisecond (file name)");
    }
  }
  check_size("--width", req.width_px);
  check_size("--height", req.height_px);
}

namespace {

// Refuses (RenderInputError) a last time past the scene's duration_s or a
// camera the model lacks, before any context is made. Past the script's
// end the hand only holds its last target: a later time shows nothing
// new, and a far one (1e6 s) would run for hours.
void check_against_scene(const RenderRequest& req, const sim::ClosedLoop& loop,
                         double last_t_s) {
  const double duration_s = loop.the_case().config().sim.duration_s;
  if (last_t_s > duration_s) {
    throw RenderInputError("--t: time " + format("%g", last_t_s) +
                           " s is past the scene's duration_s, " +
                           format("%g", duration_s) + " s (" + req.name +
                           "'s script ends there)");
  }
  if (!req.camera.empty()) {
    try {
      camera_id(loop.model(), req.camera);
    } catch (const std::invalid_argument& e) {
      throw RenderInputError(std::string("--camera: ") + e.what());
    }
  }
}

// Ticks the loop to the first tick end at or after t_s (at t = 0 one
// tick, so that the controller's output, the overlay, exists), polling
// the stop signals every 4096 ticks; `row` is the last tick's record.
void tick_to(double t_s, sim::ClosedLoop* loop, TickRecord* row,
             bool* ticked) {
  for (long n = 1; !*ticked || loop->time_s() < t_s - 1e-9; ++n) {
    loop->tick(row);
    loop->throw_if_physics_fault();  // a picture of a reset state says nothing
    *ticked = true;
    if (n % 4096 == 0) runtime::throw_if_stopped("render");
  }
}

// the label's two columns: the case, t, |F| and d_path, and their values
RenderLabel label_of(const RenderRequest& req, const RenderedImage& img) {
  RenderLabel label;
  if (req.label) {
    label.titles = req.name + "\nt\n|F|\nd_path";
    label.values = "\n" + format("%.3f s", img.sim_t_s) + "\n" +
                   format("%.2f N", img.force_N) + "\n" +
                   format("%.2f mm", img.d_path_mm);
  }
  return label;
}

// The loop's state at the time asked for, t_s, drawn with its overlay and
// label and written as a PNG into req.out_dir; `prims` is scratch for the
// overlay.
RenderedImage draw_image(const RenderRequest& req, double t_s,
                         sim::ClosedLoop* loop, const TickRecord& row,
                         SceneRenderer* renderer,
                         std::vector<OverlayPrimitive>* prims) {
  const auto start = std::chrono::steady_clock::now();
  prims->clear();
  if (req.overlays) {
    overlay_primitives(loop->controller().mechanism(),
                       loop->controller_params(), row.out, OverlayOptions(),
                       prims);
  }
  RenderedImage img;
  img.t_s = t_s;
  img.sim_t_s = loop->time_s();
  img.width_px = req.width_px;
  img.height_px = req.height_px;
  img.force_N = row.out.force_device_N.norm();
  img.d_path_mm = row.d_path_mm;
  const std::vector<std::uint8_t> rgb =
      renderer->render_rgb(loop->model(), loop->data(), *prims, req.width_px,
                           req.height_px, req.camera, label_of(req, img));
  img.path = (std::filesystem::path(req.out_dir) /
              render_file_name(req.name, t_s))
                 .string();
  write_png(img.path, req.width_px, req.height_px, rgb);
  img.render_wall_s = std::chrono::duration<double>(
                          std::chrono::steady_clock::now() - start)
                          .count();
  return img;
}

}  // namespace

std::vector<RenderedImage> render(const RenderRequest& req) {
  validate_render_request(req);
  std::vector<double> times = req.times_s;
  std::sort(times.begin(), times.end());

  sim::ClosedLoop loop(req.scene_path, req.overrides, req.model_hook);
  check_against_scene(req, loop, times.back());
  // the context first: without a display nothing is created
  GlContext gl;
  SceneRenderer renderer(loop.model(), loop.controller_params().omni,
                         req.width_px, req.height_px);
  std::error_code ec;
  std::filesystem::create_directories(req.out_dir, ec);
  if (ec) {
    throw std::runtime_error("render: cannot create folder '" + req.out_dir +
                             "': " + ec.message());
  }
  std::vector<OverlayPrimitive> prims;
  std::vector<RenderedImage> images;
  TickRecord row;
  bool ticked = false;
  for (double t : times) {
    runtime::throw_if_stopped("render");
    tick_to(t, &loop, &row, &ticked);
    runtime::throw_if_stopped("render");
    images.push_back(draw_image(req, t, &loop, row, &renderer, &prims));
  }
  return images;
}

}  // namespace vmh::viz
