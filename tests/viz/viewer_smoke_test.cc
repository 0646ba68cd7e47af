// viz/viewer under Xvfb: the viewer on case1 driven by synthetic input
// through Viewer::inject (the path GLFW's callbacks take). The mouse hand
// drags the stylus the way the cursor went; the force arrow is drawn; pause
// holds simulated time, one step advances it by one servo period, reset
// returns it to zero; a screenshot is a PNG file. No timing is asserted:
// the physics runs in real time, so the tests wait on simulated time.
#include "viz/viewer.h"

#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "viz/mouse_hand.h"

namespace vmh::viz {
namespace {

ViewerOptions case1() {
  ViewerOptions o;
  o.cases = {{"case1", VMH_MODELS_DIR "/cases/case1.xml"}};
  o.width_px = 640;
  o.height_px = 480;
  return o;
}

Vec3 site_m(const Viewer& v, const char* name) {
  const int id = mj_name2id(v.model(), mjOBJ_SITE, name);
  EXPECT_GE(id, 0) << name;
  return Vec3(v.frame_data()->site_xpos + 3 * id);
}

// frames until simulated time reaches t_s (or a generous frame budget)
void frames_until(Viewer* v, double t_s) {
  for (int i = 0; i < 5000 && v->sim_time_s() < t_s; ++i) {
    ASSERT_TRUE(v->frame());
  }
  ASSERT_GE(v->sim_time_s(), t_s);
}

ViewCamera view_camera(const Viewer& v) {
  ViewCamera c;
  const mjvCamera& m = v.camera();
  c.lookat_m = Vec3(m.lookat[0], m.lookat[1], m.lookat[2]);
  c.azimuth_deg = m.azimuth;
  c.elevation_deg = m.elevation;
  c.distance_m = m.distance;
  c.fovy_deg = v.model()->vis.global.fovy;
  return c;
}

TEST(ViewerSmoke, MouseHandDragsTheStylusAndTheForceArrowAppears) {
  Viewer v(case1());
  frames_until(&v, 0.5);  // the script's first hold, settled
  ASSERT_FALSE(v.mouse_hand());
  v.inject(InputEvent::key_press(GLFW_KEY_M));
  ASSERT_TRUE(v.mouse_hand());
  ASSERT_TRUE(v.frame());
  const Vec3 wrist0 = site_m(v, "wrist");
  const ViewCamera cam = view_camera(v);
  const Vec3 right = camera_frame(cam).right;
  const double m_per_px = metres_per_pixel(cam, wrist0, v.viewport_height_px());

  // 100 frames of drag, 0.3 px each, to the right
  double x = 320.0;
  const double y = 240.0;
  v.inject(InputEvent::click(GLFW_MOUSE_BUTTON_LEFT, true, x, y));
  for (int i = 0; i < 100; ++i) {
    x += 0.3;
    v.inject(InputEvent::move(x, y));
    ASSERT_TRUE(v.frame());
  }
  v.inject(InputEvent::click(GLFW_MOUSE_BUTTON_LEFT, false, x, y));
  // the hand holds there; let it settle for a second of simulated time
  frames_until(&v, v.sim_time_s() + 1.0);
  const Vec3 moved = site_m(v, "wrist") - wrist0;
  const double commanded_m = 30.0 * m_per_px;  // how far the target went
  const double along_m = moved.dot(right);
  std::printf("[ info     ] target dragged %.2f mm, wrist followed %.2f mm "
              "along the camera's right\n",
              1e3 * commanded_m, 1e3 * along_m);
  // the VM's spring (0.5 N/mm) resists the hand's (0.135 N/mm) across the
  // path, so the wrist need not follow all the way (about 80 % here, where
  // the drag runs mostly along the circle); but it goes the way the cursor
  // went, by a good part of it, and not past it
  EXPECT_GT(along_m, 0.3 * commanded_m)
      << "moved " << moved.transpose() << " m, target " << commanded_m << " m";
  EXPECT_LT(along_m, 1.2 * commanded_m);

  // the force arrow is in the last frame's overlay, as long as |F|
  const double F_N = v.last_output().force_device_N.norm();
  EXPECT_GT(F_N, 0.0);
  int arrows = 0;
  for (const OverlayPrimitive& p : v.last_overlay()) {
    if (p.id != OverlayId::kForce) continue;
    ++arrows;
    EXPECT_NEAR((p.b_m - p.a_m).norm(), OverlayOptions{}.force_m_per_N * F_N,
                1e-9);
  }
  EXPECT_EQ(arrows, 1);
  // overlays off: nothing drawn
  v.inject(InputEvent::key_press(GLFW_KEY_O));
  ASSERT_TRUE(v.frame());
  EXPECT_TRUE(v.last_overlay().empty());
}

TEST(ViewerSmoke, PauseStepAndReset) {
  Viewer v(case1());
  frames_until(&v, 0.1);
  v.inject(InputEvent::key_press(GLFW_KEY_SPACE));
  ASSERT_TRUE(v.paused());
  ASSERT_TRUE(v.frame());
  const double t_paused = v.sim_time_s();
  // 0.2 s of wall time paused: simulated time does not move
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
  while (std::chrono::steady_clock::now() < until) ASSERT_TRUE(v.frame());
  EXPECT_EQ(v.sim_time_s(), t_paused);
  // one servo tick (case1's 1 ms)
  v.inject(InputEvent::key_press(GLFW_KEY_RIGHT));
  for (int i = 0; i < 200 && v.sim_time_s() == t_paused; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ASSERT_TRUE(v.frame());
  }
  EXPECT_NEAR(v.sim_time_s() - t_paused, 1e-3, 1e-9);
  v.inject(InputEvent::key_press(GLFW_KEY_R));
  ASSERT_TRUE(v.frame());
  EXPECT_EQ(v.sim_time_s(), 0.0);
  v.inject(InputEvent::key_press(GLFW_KEY_SPACE));
  EXPECT_FALSE(v.paused());
  frames_until(&v, 0.05);
}

TEST(ViewerSmoke, ScreenshotIsAPng) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "vmh_viewer_smoke_shots";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ViewerOptions o = case1();
  o.out_dir = dir.string();
  Viewer v(o);
  ASSERT_TRUE(v.frame());
  v.inject(InputEvent::key_press(GLFW_KEY_P));
  ASSERT_TRUE(v.frame());
  ASSERT_FALSE(v.last_screenshot().empty());
  std::ifstream f(v.last_screenshot(), std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  std::filesystem::remove_all(dir);
}

TEST(ViewerSmoke, NextCaseAndGainsRebuildTheLoop) {
  ViewerOptions o = case1();
  o.cases.push_back({"case2", VMH_MODELS_DIR "/cases/case2.xml"});
  Viewer v(o);
  ASSERT_TRUE(v.frame());
  v.inject(InputEvent::key_press(GLFW_KEY_RIGHT_BRACKET));
  EXPECT_EQ(v.case_name(), "case2");
  v.inject(InputEvent::key_press(GLFW_KEY_LEFT_BRACKET));
  EXPECT_EQ(v.case_name(), "case1");
  v.inject(InputEvent::key_press(GLFW_KEY_EQUAL));
  EXPECT_EQ(v.gain_scale(), 2.0);
  frames_until(&v, 0.05);
}

// A live device source poses the model from its readings (device
// convention turned into the DH joints by the rules of
// controller/device_frame.h's header, written out here by hand) and runs no physics of its own.
TEST(ViewerSmoke, LiveSourcePosesTheModelFromTheReading) {
  ViewerOptions o = case1();
  Joints q_dev;
  q_dev << 0.2, 0.1, 0.35, -0.3, 0.4, 0.5;
  ControlOutput out;
  out.force_device_N = Vec3(0.5, -0.2, 0.1);
  o.live = [&] {
    LiveSample s;
    s.valid = true;
    s.t_s = 1.25;
    s.q_device_rad = q_dev;
    s.out = out;
    return s;
  };
  o.live_name = "test device";
  Viewer v(o);
  ASSERT_TRUE(v.frame());
  // q1 = -t1, q2 = t2, q3 = t3 - t2, q4 = -t4, q5 = t5, q6 = -t6
  const double q_dh[6] = {-0.2, 0.1, 0.25, 0.3, 0.4, -0.5};
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    const int j = mj_name2id(v.model(), mjOBJ_JOINT, name.c_str());
    ASSERT_GE(j, 0);
    EXPECT_NEAR(v.frame_data()->qpos[v.model()->jnt_qposadr[j]], q_dh[i],
                1e-12) << name;
  }
  EXPECT_EQ(v.sim_time_s(), 1.25);
  EXPECT_EQ(v.last_output().force_device_N, out.force_device_N);
  // keys that act on the simulation do nothing to a device
  v.inject(InputEvent::key_press(GLFW_KEY_SPACE));
  EXPECT_FALSE(v.paused());
  v.inject(InputEvent::key_press(GLFW_KEY_M));
  EXPECT_FALSE(v.mouse_hand());
}

}  // namespace
}  // namespace vmh::viz
