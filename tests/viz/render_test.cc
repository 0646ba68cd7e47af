// viz/render.h and viz/scene_renderer.h under a display (Xvfb): renders are
// byte-identical run to run, the overlay's force arrow shows where an
// independent pinhole projection of its points puts it, the arm moves
// between times, a named camera is used and a missing one is named.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "sim/closed_loop.h"
#include "tests/support/temp_mjcf.h"
#include "tests/support/read_file.h"
#include "viz/gl_context.h"
#include "viz/overlay.h"
#include "viz/render.h"
#include "viz/scene_renderer.h"

namespace {

namespace fs = std::filesystem;
using vmh::Vec3;
using vmh::viz::RenderedImage;
using vmh::viz::RenderInputError;
using vmh::viz::RenderRequest;

const std::string kCase1 = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
// case1's script pulls the hand off the circle by 2.5 s: |F| at its 3.3 N
// saturation (read from the loop in the test, not assumed)
constexpr double kPullTime_s = 2.5;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("vmh_render_" + name);
  fs::remove_all(d);
  return d;
}


RenderRequest request(const fs::path& out) {
  RenderRequest r;
  r.scene_path = kCase1;
  r.name = "case1";
  r.times_s = {0.5, kPullTime_s};
  r.width_px = 320;
  r.height_px = 240;
  r.out_dir = out.string();
  return r;
}

TEST(Render, SameRequestGivesByteIdenticalFiles) {
  const fs::path a = fresh_dir("det_a"), b = fresh_dir("det_b");
  const std::vector<RenderedImage> ia = vmh::viz::render(request(a));
  const std::vector<RenderedImage> ib = vmh::viz::render(request(b));
  ASSERT_EQ(ia.size(), 2u);
  ASSERT_EQ(ib.size(), 2u);
  for (std::size_t i = 0; i < ia.size(); ++i) {
    const std::string fa = vmh::testing::read_file(ia[i].path), fb = vmh::testing::read_file(ib[i].path);
    EXPECT_EQ(fs::path(ia[i].path).filename(), fs::path(ib[i].path).filename());
    EXPECT_EQ(fa.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_GT(fa.size(), 1000u);
    EXPECT_TRUE(fa == fb) << ia[i].path << " and " << ib[i].path << " differ";
    // informational: the wall time of drawing, reading back and writing
    std::cout << "render 320x240 at t = " << ia[i].t_s
              << " s: " << ia[i].render_wall_s << " s, "
              << ib[i].render_wall_s << " s\n";
  }
  // the names carry the time in ms, 6 digits
  EXPECT_EQ(fs::path(ia[1].path).filename(), "case1_t002500ms.png");
  EXPECT_EQ(ia[0].sim_t_s, 0.5);
  EXPECT_EQ(fs::path(ia[0].path).parent_path(), a);
}

TEST(Render, TheArmMovesBetweenTimes) {
  const fs::path out = fresh_dir("times");
  RenderRequest r = request(out);
  r.overlays = false;  // the MuJoCo scene alone: only the arm can differ
  r.label = false;
  const std::vector<RenderedImage> im = vmh::viz::render(r);
  ASSERT_EQ(im.size(), 2u);
  EXPECT_NE(vmh::testing::read_file(im[0].path), vmh::testing::read_file(im[1].path));
  // at 0.5 s the hand rests on the path, at 2.5 s it has pulled off it
  EXPECT_LT(im[0].d_path_mm, 1.0);
  EXPECT_GT(im[1].d_path_mm, 5.0);
}

// is the pixel magenta-ish (the force arrow's colour, red and blue well
// above green, whatever the shading)?
bool magenta(const std::vector<std::uint8_t>& rgb, int w, int u, int v) {
  const std::size_t k = 3u * (static_cast<std::size_t>(v) * w + u);
  const int r = rgb[k], g = rgb[k + 1], b = rgb[k + 2];
  return r > 90 && b > 90 && g < 0.6 * std::min(r, b);
}

// any magenta pixel within `radius` px of (u, v)?
bool magenta_near(const std::vector<std::uint8_t>& rgb, int w, int h,
                  double u, double v, int radius) {
  for (int dv = -radius; dv <= radius; ++dv) {
    for (int du = -radius; du <= radius; ++du) {
      const int x = static_cast<int>(std::floor(u)) + du;
      const int y = static_cast<int>(std::floor(v)) + dv;
      if (x >= 0 && y >= 0 && x < w && y < h && magenta(rgb, w, x, y)) {
        return true;
      }
    }
  }
  return false;
}

int count_magenta(const std::vector<std::uint8_t>& rgb, int w, int h) {
  int n = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) n += magenta(rgb, w, u, v) ? 1 : 0;
  }
  return n;
}

// A world point to pixel coordinates (from the top left) by a pinhole
// camera built from the scene's two eye cameras and their frustum, as
// OpenGL's glFrustum maps it (the frustum's width set by the viewport's
// aspect). Without stereo MuJoCo draws from the eyes' midpoint: they sit
// half the model's ipd either side of it.
struct Pixel {
  double u, v;
};
Pixel project(const mjvScene& scn, int w, int h, const Vec3& p) {
  const mjvGLCamera& c = scn.camera[0];
  const mjvGLCamera& c1 = scn.camera[1];
  const Vec3 pos = 0.5 * (Vec3(c.pos[0], c.pos[1], c.pos[2]) +
                          Vec3(c1.pos[0], c1.pos[1], c1.pos[2]));
  const Vec3 fwd = Vec3(c.forward[0], c.forward[1], c.forward[2]).normalized();
  const Vec3 right = fwd.cross(Vec3(c.up[0], c.up[1], c.up[2])).normalized();
  const Vec3 up = right.cross(fwd);
  const Vec3 rel = p - pos;
  const double z = rel.dot(fwd);
  const double x_near = rel.dot(right) * c.frustum_near / z;
  const double y_near = rel.dot(up) * c.frustum_near / z;
  const double half_h = 0.5 * (c.frustum_top - c.frustum_bottom);
  const double half_w = half_h * w / h;
  const double left = c.frustum_center - half_w;
  return Pixel{(x_near - left) / (2.0 * half_w) * w,
               (c.frustum_top - y_near) / (2.0 * half_h) * h};
}

TEST(SceneRenderer, ForceArrowIsDrawnWhereItProjects) {
  vmh::sim::ClosedLoop loop(kCase1, {});
  vmh::TickRecord row;
  while (loop.time_s() < kPullTime_s - 1e-9) loop.tick(&row);
  const double f_N = row.out.force_device_N.norm();
  ASSERT_GT(f_N, 1.0) << "case1 should push back hard at " << kPullTime_s;

  std::vector<vmh::viz::OverlayPrimitive> prims;
  vmh::viz::overlay_primitives(loop.controller().mechanism(),
                               loop.controller_params(), row.out,
                               vmh::viz::OverlayOptions(), &prims);
  const vmh::viz::OverlayPrimitive* arrow = nullptr;
  for (const auto& p : prims) {
    if (p.id == vmh::viz::OverlayId::kForce) arrow = &p;
  }
  ASSERT_NE(arrow, nullptr);

  const int w = 640, h = 480;
  vmh::viz::GlContext gl;
  vmh::viz::SceneRenderer r(loop.model(), loop.controller_params().omni, w, h);
  const auto all = r.render_rgb(loop.model(), loop.data(), prims, w, h, "");
  // the arrow alone for the projection: the VM's links lie along it when
  // the hand is pulled straight off the circle, and hide parts of it
  const auto with = r.render_rgb(loop.model(), loop.data(), {*arrow}, w, h, "");
  const mjvScene& cam = r.scene();
  std::vector<Pixel> px;
  for (double s : {0.2, 0.35, 0.5, 0.65}) {
    px.push_back(project(cam, w, h, arrow->a_m + s * (arrow->b_m - arrow->a_m)));
  }
  const Vec3 mid = 0.5 * (arrow->a_m + arrow->b_m);
  const Pixel far = project(cam, w, h, mid + Vec3(0.0, 0.0, 0.12));
  const auto without = r.render_rgb(loop.model(), loop.data(), {}, w, h, "");
  ASSERT_EQ(with.size(), 3u * w * h);
  EXPECT_NE(all, without);
  EXPECT_NE(with, without);
  // magenta only where the arrow is drawn: the scene itself has none
  EXPECT_EQ(count_magenta(without, w, h), 0);
  EXPECT_GT(count_magenta(all, w, h), 10);
  EXPECT_GT(count_magenta(with, w, h), 10);

  // points along the arrow's shaft (its head is wider); the wrist's
  // gimbal may hide a few, not most
  int seen = 0, tried = 0;
  for (const Pixel& p : px) {
    ASSERT_TRUE(p.u > 0 && p.u < w && p.v > 0 && p.v < h)
        << "the arrow leaves the default view at (" << p.u << ", " << p.v
        << ")";
    ++tried;
    if (magenta_near(with, w, h, p.u, p.v, 3)) ++seen;
    EXPECT_FALSE(magenta_near(without, w, h, p.u, p.v, 3));
  }
  EXPECT_GE(seen, tried - 1) << seen << " of " << tried
                             << " arrow points are magenta in the image";
  // and far from the arrow (the VM circle's opposite side) no magenta
  EXPECT_FALSE(magenta_near(with, w, h, far.u, far.v, 3));
}

TEST(SceneRenderer, MissingCameraIsNamedWithTheModelsCameras) {
  vmh::sim::ClosedLoop loop(kCase1, {});
  try {
    vmh::viz::camera_id(loop.model(), "nosuchcam");
    FAIL() << "no error for a missing camera";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'nosuchcam'"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("front, three_quarter, side, top"),
              std::string::npos)
        << e.what();
  }
  RenderRequest r = request(fresh_dir("nocam"));
  r.camera = "nosuchcam";
  try {
    vmh::viz::render(r);
    FAIL() << "render took a missing camera";
  } catch (const RenderInputError& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchcam"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(r.out_dir)) << "nothing is written for bad input";
}

// case1 with a camera added: a scene beside links to the model folders
// (its includes are relative)
TEST(SceneRenderer, NamedCameraIsUsed) {
  vmh::testing::TempMjcfDir tmp;
  const fs::path dir = fs::path(tmp.write("x", "")).parent_path();
  fs::create_directory_symlink(fs::path(VMH_MODELS_DIR) / "omni", dir / "omni");
  fs::create_directory_symlink(fs::path(VMH_MODELS_DIR) / "hand", dir / "hand");
  fs::create_directories(dir / "cases");
  std::string xml = vmh::testing::read_file(kCase1);
  const std::size_t end = xml.rfind("</mujoco>");
  ASSERT_NE(end, std::string::npos);
  xml.insert(end,
             "  <worldbody>\n    <camera name=\"above\" pos=\"0.1 0 0.5\" "
             "xyaxes=\"0 1 0 -1 0 0\"/>\n    <camera name=\"other\" "
             "pos=\"0.5 0 0\" xyaxes=\"0 1 0 0 0 1\"/>\n  </worldbody>\n");
  const fs::path scene = dir / "cases" / "with_camera.xml";
  {
    std::ofstream out(scene);
    out << xml;
  }
  RenderRequest r = request(fresh_dir("cam"));
  r.scene_path = scene.string();
  r.times_s = {0.5};
  const RenderedImage free_view = vmh::viz::render(r).at(0);
  const std::string free_png = vmh::testing::read_file(free_view.path);
  r.camera = "above";
  const RenderedImage above = vmh::viz::render(r).at(0);
  EXPECT_NE(vmh::testing::read_file(above.path), free_png);

  r.camera = "missing";
  try {
    vmh::viz::render(r);
    FAIL() << "render took a missing camera";
  } catch (const RenderInputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'missing'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("above, other"), std::string::npos) << msg;
  }
}

TEST(RenderRequest, BadInputIsNamed) {
  const auto message = [](const RenderRequest& r) -> std::string {
    try {
      vmh::viz::validate_render_request(r);
    } catch (const RenderInputError& e) {
      return e.what();
    }
    return "";
  };
  RenderRequest r = request(fresh_dir("bad"));
  EXPECT_EQ(message(r), "");
  r.times_s = {0.5, -1.0};
  EXPECT_NE(message(r).find("-1"), std::string::npos) << message(r);
  r.times_s = {std::nan("")};
  EXPECT_NE(message(r).find("nan"), std::string::npos) << message(r);
  r.times_s = {1.0, 1.0004};
  EXPECT_NE(message(r).find("same millisecond"), std::string::npos);
  r.times_s = {};
  EXPECT_NE(message(r).find("no times"), std::string::npos);
  r = request(fresh_dir("bad"));
  r.width_px = 3;
  EXPECT_NE(message(r).find("--width: 3 px"), std::string::npos) << message(r);
  r.width_px = 640;
  r.height_px = 5000;
  EXPECT_NE(message(r).find("--height: 5000 px"), std::string::npos);
}

TEST(RenderFileName, CarriesTheTimeInMilliseconds) {
  EXPECT_EQ(vmh::viz::render_file_name("case1", 2.5), "case1_t002500ms.png");
  EXPECT_EQ(vmh::viz::render_file_name("case3", 0.0), "case3_t000000ms.png");
  EXPECT_EQ(vmh::viz::render_file_name("x", 1234.5678), "x_t1234568ms.png");
}

}  // namespace

namespace {

// The named cameras of models/omni/stage.xml frame the whole device and
// its VM, lit, at 4:3 and at 16:9 (issue 31). Case 1 at 5 s, when the hand
// has raised the upper arm above the shoulder (the highest pose of its
// script), seen by each camera:
//   - the device (every geom but the desk, from MuJoCo's segmentation
//     rendering) covers between 4 % and 60 % of the frame, and none of its
//     pixels lies on the frame's border: it is all in the picture;
//   - the mean luminance of its pixels in the ordinary render (Rec. 709
//     weights, 0..255) is at least 70: it is lit, not a silhouette;
//   - the VM's circle (48 points of it) projects inside the frame.
// The figures are printed, for docs/viewer.md.
TEST(SceneRenderer, EveryNamedCameraFramesTheWholeLitDevice) {
  vmh::sim::ClosedLoop loop(kCase1, {});
  vmh::TickRecord row;
  while (loop.time_s() < 5.0 - 1e-9) loop.tick(&row);
  std::vector<vmh::viz::OverlayPrimitive> path;
  vmh::viz::OverlayOptions opt;
  opt.mechanism = opt.stylus = opt.force = false;
  opt.circle_segments = 48;
  vmh::viz::overlay_primitives(loop.controller().mechanism(),
                               loop.controller_params(), row.out, opt, &path);
  ASSERT_EQ(path.size(), 48u);
  const mjModel* m = loop.model();
  const int desk = mj_name2id(m, mjOBJ_GEOM, "desk");
  ASSERT_GE(desk, 0);
  vmh::viz::GlContext gl;
  vmh::viz::SceneRenderer r(m, loop.controller_params().omni, 640, 480);
  const std::vector<std::string> cams = vmh::viz::camera_names(m);
  ASSERT_EQ(cams, (std::vector<std::string>{"front", "three_quarter", "side", "top"}));
  for (const std::string& cam : cams) {
    for (const auto& [w, h] : {std::pair{640, 480}, std::pair{640, 360}}) {
      SCOPED_TRACE(cam + " " + std::to_string(w) + "x" + std::to_string(h));
      const std::vector<int> ids = r.render_geom_ids(m, loop.data(), w, h, cam);
      const std::vector<std::uint8_t> rgb =
          r.render_rgb(m, loop.data(), {}, w, h, cam);
      long device = 0, border = 0;
      double luminance = 0.0;
      for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
          const std::size_t i = static_cast<std::size_t>(v) * w + u;
          if (ids[i] < 0 || ids[i] == desk) continue;
          ++device;
          if (u == 0 || v == 0 || u == w - 1 || v == h - 1) ++border;
          luminance += 0.2126 * rgb[3 * i] + 0.7152 * rgb[3 * i + 1] +
                       0.0722 * rgb[3 * i + 2];
        }
      }
      const double share = static_cast<double>(device) / (w * h);
      const double mean_lum =
          device > 0 ? luminance / static_cast<double>(device) : 0.0;
      std::cout << "camera " << cam << " " << w << "x" << h
                << ": device share " << share << ", mean luminance "
                << mean_lum << "\n";
      EXPECT_GT(share, 0.04);
      EXPECT_LT(share, 0.60);
      EXPECT_EQ(border, 0) << "the device is cut by the frame's edge";
      EXPECT_GT(mean_lum, 70.0);
      for (const auto& seg : path) {
        const Pixel p = project(r.scene(), w, h, seg.a_m);
        EXPECT_TRUE(p.u > 0 && p.u < w && p.v > 0 && p.v < h)
            << "the VM's path leaves the frame at (" << p.u << ", " << p.v << ")";
      }
    }
  }
}

}  // namespace
