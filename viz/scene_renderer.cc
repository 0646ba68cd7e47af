#include "viz/scene_renderer.h"

#include <algorithm>
#include <stdexcept>

#include "controller/device_frame.h"
#include "viz/png.h"

namespace vmh::viz {
namespace {

// room for the model's geoms and the overlay's (a sphere path has three
// circles of ~100 segments, a surface grid fewer)
constexpr int kMaxGeom = 4000;

void check_size(const char* what, int px) {
  if (px < 16 || px > 4096) {
    throw std::invalid_argument(std::string(what) + " " + std::to_string(px) +
                                " px is outside [16, 4096]");
  }
}

}  // namespace

mjvCamera workspace_camera(const OmniParams& omni) {
  mjvCamera cam;
  mjv_defaultCamera(&cam);
  cam.type = mjCAMERA_FREE;
  // near the device-frame origin (the thesis's VMs are pivoted there),
  // pulled a little toward the shoulder, world m
  const Vec3 origin_m = device_mm_to_base(omni, Vec3::Zero());
  for (int i = 0; i < 3; ++i) cam.lookat[i] = 0.85 * origin_m[i];
  // 0.33 m: the 100 mm circle or sphere fills about a third of the height
  // at MuJoCo's default 45 degree field of view, with the forearm and the
  // upper arm in the frame
  cam.distance = 0.33;
  // azimuth 180 would look straight down -x (the device's -z); 160 turns
  // the view enough to show the arm's depth
  cam.azimuth = 160.0;
  cam.elevation = -15.0;
  return cam;
}

int camera_id(const mjModel* m, const std::string& name) {
  const int id = mj_name2id(m, mjOBJ_CAMERA, name.c_str());
  if (id >= 0) return id;
  std::string names;
  for (int i = 0; i < m->ncam; ++i) {
    const char* n = mj_id2name(m, mjOBJ_CAMERA, i);
    names += (names.empty() ? "" : ", ") +
             (n != nullptr ? std::string(n) : "#" + std::to_string(i));
  }
  throw std::invalid_argument(
      "camera '" + name + "' not found in the model (" +
      (names.empty() ? std::string("it has no named cameras")
                     : "its cameras: " + names) +
      "; leave --camera out for the default view)");
}

SceneRenderer::SceneRenderer(const mjModel* m, const OmniParams& omni,
                             int max_width_px, int max_height_px)
    : m_(m), free_cam_(workspace_camera(omni)) {
  check_size("width", max_width_px);
  check_size("height", max_height_px);
  mjv_defaultScene(&scn_);
  mjv_defaultOption(&opt_);
  mjr_defaultContext(&con_);
  mjv_makeScene(m, &scn_, kMaxGeom);
  // mjr_makeContext only reads the model: a copy of its header (sharing
  // the arrays) carries the buffer size without changing the caller's model
  mjModel sized = *m;
  if (sized.vis.global.offwidth < max_width_px) {
    sized.vis.global.offwidth = max_width_px;
  }
  if (sized.vis.global.offheight < max_height_px) {
    sized.vis.global.offheight = max_height_px;
  }
  mjr_makeContext(&sized, &con_, mjFONTSCALE_150);
  mjr_setBuffer(mjFB_OFFSCREEN, &con_);
  if (con_.currentBuffer != mjFB_OFFSCREEN || con_.offWidth < max_width_px ||
      con_.offHeight < max_height_px) {
    mjr_freeContext(&con_);
    mjv_freeScene(&scn_);
    throw std::runtime_error("render: could not make an offscreen buffer of " +
                             std::to_string(max_width_px) + " x " +
                             std::to_string(max_height_px) + " px");
  }
}

SceneRenderer::~SceneRenderer() {
  mjr_freeContext(&con_);
  mjv_freeScene(&scn_);
}

std::vector<std::uint8_t> SceneRenderer::render_rgb(
    const mjModel* m, mjData* d, const std::vector<OverlayPrimitive>& overlay,
    int width_px, int height_px, const std::string& camera,
    const RenderLabel& label) {
  if (m != m_) {
    throw std::invalid_argument("render: a model other than the renderer's");
  }
  check_size("width", width_px);
  check_size("height", height_px);
  if (width_px > con_.offWidth || height_px > con_.offHeight) {
    throw std::invalid_argument(
        "render: " + std::to_string(width_px) + " x " +
        std::to_string(height_px) + " px is larger than the buffer (" +
        std::to_string(con_.offWidth) + " x " +
        std::to_string(con_.offHeight) + ")");
  }
  mjvCamera cam = free_cam_;
  if (!camera.empty()) {
    mjv_defaultCamera(&cam);
    cam.type = mjCAMERA_FIXED;
    cam.fixedcamid = camera_id(m, camera);
  }
  mjv_updateScene(m, d, &opt_, nullptr, &cam, mjCAT_ALL, &scn_);
  // the case scenes have no lights of their own (models/cases/*.xml):
  // a brighter headlight than MuJoCo's default shows the arm's shape
  if (scn_.nlight > 0 && scn_.lights[0].headlight) {
    for (int i = 0; i < 3; ++i) {
      scn_.lights[0].ambient[i] = std::max(scn_.lights[0].ambient[i], 0.3f);
      scn_.lights[0].diffuse[i] = std::max(scn_.lights[0].diffuse[i], 0.7f);
    }
  }
  add_overlay_to_scene(overlay, &scn_);

  mjr_setBuffer(mjFB_OFFSCREEN, &con_);
  const mjrRect viewport{0, 0, width_px, height_px};
  mjr_render(viewport, &scn_, &con_);
  if (!label.titles.empty() || !label.values.empty()) {
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport,
                label.titles.c_str(), label.values.c_str(), &con_);
  }
  std::vector<std::uint8_t> rgb(3u * static_cast<std::size_t>(width_px) *
                                static_cast<std::size_t>(height_px));
  mjr_readPixels(rgb.data(), nullptr, viewport, &con_);
  flip_rows(width_px, height_px, &rgb);
  return rgb;
}

}  // namespace vmh::viz
