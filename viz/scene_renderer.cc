#include "viz/scene_renderer.h"

#include <algorithm>
#include <cmath>
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

mjvCamera default_camera(const mjModel* m, const OmniParams& omni) {
  const int id = mj_name2id(m, mjOBJ_CAMERA, "three_quarter");
  if (id < 0) return workspace_camera(omni);
  mjvCamera cam;
  mjv_defaultCamera(&cam);
  cam.type = mjCAMERA_FIXED;
  cam.fixedcamid = id;
  return cam;
}

mjvCamera free_camera_like(const mjModel* m, int cam_id) {
  mjvCamera cam;
  mjv_defaultFreeCamera(m, &cam);
  if (cam_id < 0 || cam_id >= m->ncam) return cam;
  mjtNum R[9];
  mju_quat2Mat(R, m->cam_quat + 4 * cam_id);
  const mjtNum* p = m->cam_pos + 3 * cam_id;
  // a camera looks along its -z axis
  const Vec3 f(-R[2], -R[5], -R[8]);
  const Vec3 eye(p[0], p[1], p[2]);
  const Vec3 centre(m->stat.center[0], m->stat.center[1], m->stat.center[2]);
  double depth = (centre - eye).dot(f);
  if (!(depth > 1e-3)) depth = 0.5;
  const double deg = 3.14159265358979323846 / 180.0;
  const double scale = std::tan(0.5 * m->cam_fovy[cam_id] * deg) /
                       std::tan(0.5 * m->vis.global.fovy * deg);
  const Vec3 lookat = eye + depth * f;
  for (int i = 0; i < 3; ++i) cam.lookat[i] = lookat[i];
  cam.distance = depth * scale;
  cam.azimuth = std::atan2(f.y(), f.x()) / deg;
  cam.elevation = std::asin(std::clamp(f.z(), -1.0, 1.0)) / deg;
  return cam;
}

std::vector<std::string> camera_names(const mjModel* m) {
  std::vector<std::string> names;
  for (int i = 0; i < m->ncam; ++i) {
    const char* n = mj_id2name(m, mjOBJ_CAMERA, i);
    names.push_back(n != nullptr ? std::string(n) : "#" + std::to_string(i));
  }
  return names;
}

void prepare_scene(const mjModel* m, mjData* d, const mjvOption* opt,
                   mjvCamera* cam, const std::vector<OverlayPrimitive>& overlay,
                   mjvScene* scn) {
  mjv_updateScene(m, d, opt, nullptr, cam, mjCAT_ALL, scn);
  // a scene without lights (a user's scene without models/omni/stage.xml):
  // a brighter headlight than MuJoCo's default shows the arm's shape
  if (m->nlight == 0 && scn->nlight > 0 && scn->lights[0].headlight) {
    for (int i = 0; i < 3; ++i) {
      scn->lights[0].ambient[i] = std::max(scn->lights[0].ambient[i], 0.3f);
      scn->lights[0].diffuse[i] = std::max(scn->lights[0].diffuse[i], 0.7f);
    }
  }
  add_overlay_to_scene(overlay, scn);
  const int body = mj_name2id(m, mjOBJ_BODY, "hand_target");
  const int grip = mj_name2id(m, mjOBJ_SITE, "grip");
  const int mocap = body >= 0 ? m->body_mocapid[body] : -1;
  if (mocap >= 0 && grip >= 0) {
    const mjtNum* p = d->mocap_pos + 3 * mocap;
    mjtNum R[9];
    mju_quat2Mat(R, d->mocap_quat + 4 * mocap);
    Mat3 target_R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) target_R(r, c) = R[3 * r + c];
    }
    const mjtNum* g = d->site_xpos + 3 * grip;
    std::vector<OverlayPrimitive> hand;
    hand_primitives(Vec3(p[0], p[1], p[2]), target_R, Vec3(g[0], g[1], g[2]),
                    &hand);
    add_overlay_to_scene(hand, scn, 1.0f);
  }
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
    : m_(m), free_cam_(default_camera(m, omni)) {
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
  prepare_scene(m, d, &opt_, &cam, overlay, &scn_);

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

std::vector<int> SceneRenderer::render_geom_ids(const mjModel* m, mjData* d,
                                                int width_px, int height_px,
                                                const std::string& camera) {
  // the colour of segid s is s + 1 in (r, g, b) = (low, middle, high) byte
  scn_.flags[mjRND_SEGMENT] = 1;
  scn_.flags[mjRND_IDCOLOR] = 1;
  std::vector<std::uint8_t> rgb;
  try {
    rgb = render_rgb(m, d, {}, width_px, height_px, camera);
  } catch (...) {
    scn_.flags[mjRND_SEGMENT] = 0;
    scn_.flags[mjRND_IDCOLOR] = 0;
    throw;
  }
  scn_.flags[mjRND_SEGMENT] = 0;
  scn_.flags[mjRND_IDCOLOR] = 0;
  std::vector<int> ids(static_cast<std::size_t>(width_px) *
                       static_cast<std::size_t>(height_px), -1);
  // segid -> the model geom drawn with it
  std::vector<int> geom_of_seg;
  for (int k = 0; k < scn_.ngeom; ++k) {
    const mjvGeom& g = scn_.geoms[k];
    if (g.segid < 0 || g.objtype != mjOBJ_GEOM) continue;
    if (static_cast<std::size_t>(g.segid) >= geom_of_seg.size()) {
      geom_of_seg.resize(static_cast<std::size_t>(g.segid) + 1, -1);
    }
    geom_of_seg[static_cast<std::size_t>(g.segid)] = g.objid;
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const int seg = rgb[3 * i] + 256 * rgb[3 * i + 1] + 65536 * rgb[3 * i + 2] - 1;
    if (seg >= 0 && static_cast<std::size_t>(seg) < geom_of_seg.size()) {
      ids[i] = geom_of_seg[static_cast<std::size_t>(seg)];
    }
  }
  return ids;
}

}  // namespace vmh::viz
