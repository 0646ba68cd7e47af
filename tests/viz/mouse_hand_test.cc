// viz/mouse_hand: a dragged target projected back to the screen with
// MuJoCo's own camera (mjv_updateScene's mjvScene::camera, its frame and
// frustum) follows the cursor; a rotating drag stays a rotation about the
// camera's axes. No window: the scene is updated, never rendered.
#include "viz/mouse_hand.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <mujoco/mujoco.h>

namespace vmh::viz {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

// window pixel (x right, y down) of a world point through MuJoCo's own
// OpenGL camera, as mjr_render sets up the projection: the frustum at the
// near plane spans (top - bottom) vertically over the viewport's height,
// and the same metres per pixel horizontally about frustum_center
Eigen::Vector2d project_px(const mjvGLCamera& c, int width_px, int height_px,
                           const Vec3& p_m) {
  const Vec3 pos(c.pos[0], c.pos[1], c.pos[2]);
  const Vec3 fwd(c.forward[0], c.forward[1], c.forward[2]);
  const Vec3 up(c.up[0], c.up[1], c.up[2]);
  const Vec3 right = fwd.cross(up);
  const Vec3 v = p_m - pos;
  const double z = v.dot(fwd);
  const double x_near = c.frustum_near * v.dot(right) / z;
  const double y_near = c.frustum_near * v.dot(up) / z;
  const double m_per_px =
      (c.frustum_top - c.frustum_bottom) / static_cast<double>(height_px);
  return Eigen::Vector2d(0.5 * width_px + (x_near - c.frustum_center) / m_per_px,
                         (c.frustum_top - y_near) / m_per_px);
}

class MouseHandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char err[1000] = "";
    m_.reset(mj_loadXML(VMH_MODELS_DIR "/cases/case1.xml", nullptr, err,
                        sizeof err));
    ASSERT_TRUE(m_) << err;
    d_.reset(mj_makeData(m_.get()));
    mj_forward(m_.get(), d_.get());
    mjv_defaultOption(&opt_);
    mjv_defaultScene(&scn_);
    mjv_makeScene(m_.get(), &scn_, 2000);
  }
  void TearDown() override { mjv_freeScene(&scn_); }

  // MuJoCo's camera for `cam` (updated by MuJoCo, not by mouse_hand): the
  // two eyes' cameras (ipd apart) averaged, as mjr_render does without
  // stereo
  mjvGLCamera gl_camera(const ViewCamera& cam) {
    mjvCamera c;
    mjv_defaultCamera(&c);
    c.type = mjCAMERA_FREE;
    for (int i = 0; i < 3; ++i) c.lookat[i] = cam.lookat_m[i];
    c.azimuth = cam.azimuth_deg;
    c.elevation = cam.elevation_deg;
    c.distance = cam.distance_m;
    mjv_updateScene(m_.get(), d_.get(), &opt_, nullptr, &c, mjCAT_ALL, &scn_);
    return mjv_averageCamera(scn_.camera, scn_.camera + 1);
  }

  std::unique_ptr<mjModel, ModelDeleter> m_;
  std::unique_ptr<mjData, DataDeleter> d_;
  mjvOption opt_;
  mjvScene scn_;
};

TEST_F(MouseHandTest, FrameMatchesMujocosCamera) {
  ViewCamera cam;
  cam.lookat_m = Vec3(0.05, -0.02, 0.1);
  cam.azimuth_deg = 130.0;
  cam.elevation_deg = -25.0;
  cam.distance_m = 0.6;
  const mjvGLCamera gl = gl_camera(cam);
  const CameraFrame f = camera_frame(cam);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(f.eye_m[i], gl.pos[i], 1e-6);
    EXPECT_NEAR(f.forward[i], gl.forward[i], 1e-6);
    EXPECT_NEAR(f.up[i], gl.up[i], 1e-6);
  }
}

TEST_F(MouseHandTest, DraggedTargetFollowsTheCursor) {
  const int width_px = 1200, height_px = 900;
  const Vec3 target_m(0.12, 0.03, 0.08);
  for (double az : {90.0, 150.0, -40.0}) {
    for (double el : {-45.0, -10.0, 20.0}) {
      ViewCamera cam;
      cam.lookat_m = Vec3(0.0, 0.0, 0.05);
      cam.azimuth_deg = az;
      cam.elevation_deg = el;
      cam.distance_m = 0.5;
      cam.fovy_deg = m_->vis.global.fovy;
      const mjvGLCamera gl = gl_camera(cam);
      const Eigen::Vector2d before = project_px(gl, width_px, height_px, target_m);
      for (const Eigen::Vector2d& drag :
           {Eigen::Vector2d(40.0, 0.0), Eigen::Vector2d(0.0, -25.0),
            Eigen::Vector2d(-17.5, 33.0)}) {
        sim::HandTargetState t;
        t.p_m = target_m;
        t.v_m_s = Vec3::Constant(1.0);
        apply_drag(cam, height_px, drag.x(), drag.y(), false, &t);
        const Eigen::Vector2d after = project_px(gl, width_px, height_px, t.p_m);
        // the target stays at its depth, so the cursor's move is reproduced
        // to within a small fraction of a pixel (MuJoCo's camera is float)
        EXPECT_NEAR(after.x() - before.x(), drag.x(), 0.02)
            << "az " << az << " el " << el;
        EXPECT_NEAR(after.y() - before.y(), drag.y(), 0.02)
            << "az " << az << " el " << el;
        EXPECT_EQ(t.v_m_s, Vec3::Zero());  // held where the mouse left it
      }
    }
  }
}

TEST_F(MouseHandTest, RotatingDragTurnsAboutTheRightAxis) {
  ViewCamera cam;
  cam.azimuth_deg = 60.0;
  cam.elevation_deg = -30.0;
  const CameraFrame f = camera_frame(cam);
  sim::HandTargetState t;
  t.R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mat3 R0 = t.R;
  const Vec3 p0 = Vec3(0.1, 0.2, 0.3);
  t.p_m = p0;
  for (int i = 0; i < 50; ++i) apply_drag(cam, 900, 0.0, 2.0, true, &t);
  EXPECT_NEAR((t.R.transpose() * t.R - Mat3::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(t.R.determinant(), 1.0, 1e-12);
  EXPECT_EQ(t.p_m, p0);  // turned about its own position
  const Eigen::AngleAxisd turn(t.R * R0.transpose());
  EXPECT_NEAR(turn.angle(), 100.0 * kDragRadPerPx, 1e-9);
  EXPECT_NEAR(std::abs(turn.axis().dot(f.right)), 1.0, 1e-9);
  // the right axis is horizontal (MuJoCo's camera never rolls)
  EXPECT_NEAR(f.right.z(), 0.0, 1e-12);
}

TEST_F(MouseHandTest, HorizontalDragTurnsAboutUp) {
  ViewCamera cam;
  cam.azimuth_deg = -20.0;
  cam.elevation_deg = 15.0;
  const Mat3 R = drag_rotation(cam, 30.0, 0.0, 0.01);
  const Eigen::AngleAxisd turn(R);
  EXPECT_NEAR(turn.angle(), 0.3, 1e-12);
  EXPECT_NEAR(std::abs(turn.axis().dot(camera_frame(cam).up)), 1.0, 1e-12);
}

TEST(MouseHand, BadViewportOrPointBehindIsRefused) {
  ViewCamera cam;
  EXPECT_THROW(metres_per_pixel(cam, cam.lookat_m, 0), std::invalid_argument);
  const Vec3 behind = camera_frame(cam).eye_m - camera_frame(cam).forward;
  EXPECT_THROW(metres_per_pixel(cam, behind, 900), std::invalid_argument);
  // one pixel at the lookat point, by hand: 2 d tan(fovy/2) / H
  EXPECT_NEAR(metres_per_pixel(cam, cam.lookat_m, 1000),
              2.0 * 0.5 * std::tan(22.5 * M_PI / 180.0) / 1000.0, 1e-15);
}

}  // namespace
}  // namespace vmh::viz
