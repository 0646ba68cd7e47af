// viz/viewer on a served emulator (view --serve-hd) under Xvfb: a client
// program's torque moves the emulated Omni the viewer shows, the overlay
// draws the client's force and not the case's mechanism, and the mouse
// grabs the stylus, carries it and lets go. The client is this process's
// own ServedBackend on the shared-memory device, as another program's
// would be. No timing is asserted: everything waits on simulated time, and
// what depends on two wall-clock threads (the client's torque reaching the
// emulator) is waited for, not timed.
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <string>

#include "hw/served/served_device.h"
#include "sim/closed_loop.h"
#include "sim/served_emulator.h"
#include "viz/mouse_hand.h"
#include "viz/viewer.h"

namespace vmh::viz {
namespace {

constexpr const char* kScene = VMH_MODELS_DIR "/cases/case1.xml";

// a client's loop: a constant torque on the motors while on
class TorqueLoop final : public ServoLoop {
 public:
  explicit TorqueLoop(HapticDevice* d) : d_(d) {}
  bool tick(double) noexcept override {
    DeviceState s;
    d_->read_state(&s);
    d_->write_motor_torques(on_.load() ? Vec3(0.03, 0.0, 0.0) : Vec3::Zero());
    return true;
  }
  std::atomic<bool> on_{true};

 private:
  HapticDevice* d_;
};

void frames_until(Viewer* v, double t_s) {
  for (int i = 0; i < 5000 && v->sim_time_s() < t_s; ++i) {
    ASSERT_TRUE(v->frame());
  }
  ASSERT_GE(v->sim_time_s(), t_s);
}

double q_dh(const Viewer& v, const char* joint) {
  const int j = mj_name2id(v.model(), mjOBJ_JOINT, joint);
  EXPECT_GE(j, 0) << joint;
  return v.frame_data()->qpos[v.model()->jnt_qposadr[j]];
}

Vec3 site_m(const Viewer& v, const char* name) {
  const int id = mj_name2id(v.model(), mjOBJ_SITE, name);
  EXPECT_GE(id, 0) << name;
  return Vec3(v.frame_data()->site_xpos + 3 * id);
}

TEST(ViewerServed, AClientMovesTheOmniAndTheMouseGrabsTheStylus) {
  sim::ServedEmulatorOptions so;
  so.name = "viewer-test-" + std::to_string(::getpid());
  so.scene = kScene;
  so.realtime_priority = 0;
  sim::ServedEmulator served(so);
  served.start();
  ViewerOptions o;
  o.cases = {{"case1", kScene}};
  o.served = &served;
  o.width_px = 640;
  o.height_px = 480;
  Viewer v(o);
  EXPECT_TRUE(v.mouse_hand());
  frames_until(&v, 0.2);
  const double q1_before = q_dh(v, "q1");

  // the client: +30 mN m on motor 1 turns t1 positively, which is the DH
  // q1 negatively (q1 = -t1, controller/device_frame.h)
  hw::served::ServedBackend client(served.name());
  TorqueLoop loop(client.device());
  ServoOptions servo;
  servo.realtime = false;
  client.start(&loop, servo);
  // on a busy host the client's or the server's thread may starve past the
  // 50 ms watchdogs, which then hold zero torque for a while: wait (on
  // simulated time, up to 20 s of it) for the torque to act, and judge its
  // direction, not how soon
  const double t_give_up = v.sim_time_s() + 20.0;
  double turned = 0.0;
  while (v.sim_time_s() < t_give_up) {
    ASSERT_TRUE(v.frame());
    turned = q_dh(v, "q1") - q1_before;
    if (turned < -0.01 && v.last_output().force_device_N.norm() > 0.0) break;
  }
  const hw::served::ServerStats st = served.server();
  std::printf("[ info     ] q1 turned %.4f rad under +30 mN m on motor 1 "
              "(server: %ld ticks, %llu commands, command %s, truth torque "
              "%.3f N m, %ld periods, %ld dropped)\n",
              turned, st.ticks, static_cast<unsigned long long>(st.commands),
              hw::served::command_state_name(st.command_state),
              served.truth().motor_torque_Nm[0], served.truth().periods,
              served.truth().lag_periods);
  EXPECT_LT(turned, -0.01);
  // the overlay draws the client's force at the stylus, not the case's
  // mechanism; the panel names the served device and its client
  EXPECT_GT(v.last_output().force_device_N.norm(), 0.0);
  int force = 0, mechanism = 0;
  for (const OverlayPrimitive& p : v.last_overlay()) {
    if (p.id == OverlayId::kForce) ++force;
    if (p.id == OverlayId::kPath || p.id == OverlayId::kLinkV) ++mechanism;
  }
  EXPECT_EQ(force, 1);
  EXPECT_EQ(mechanism, 0);
  EXPECT_EQ(served.server().client_pid, ::getpid());
  EXPECT_EQ(served.server().command_state, hw::served::CommandState::kApplied);

  // the client lets go of the motors; the mouse grabs the stylus
  loop.on_.store(false);
  frames_until(&v, v.sim_time_s() + 0.3);
  EXPECT_FALSE(served.held());
  v.inject(InputEvent::click(GLFW_MOUSE_BUTTON_LEFT, true, 320.0, 240.0));
  EXPECT_TRUE(served.held());
  // grabbed where the grip is: nothing jumps
  const int g = served.loop().hand().grip_site();
  EXPECT_LT((served.target().p_m - Vec3(v.frame_data()->site_xpos + 3 * g)).norm(),
            1e-12);
  const Vec3 wrist0 = site_m(v, "wrist");
  ViewCamera cam;
  const mjvCamera& c = v.camera();
  cam.lookat_m = Vec3(c.lookat[0], c.lookat[1], c.lookat[2]);
  cam.azimuth_deg = c.azimuth;
  cam.elevation_deg = c.elevation;
  cam.distance_m = c.distance;
  cam.fovy_deg = v.model()->vis.global.fovy;
  const Vec3 right = camera_frame(cam).right;
  const Vec3 target0 = served.target().p_m;
  double x = 320.0;
  for (int i = 0; i < 40; ++i) {
    x += 0.5;
    v.inject(InputEvent::move(x, 240.0));
  }
  ASSERT_TRUE(v.frame());
  const double dragged_m = (served.target().p_m - target0).dot(right);
  EXPECT_GT(dragged_m, 0.0);
  frames_until(&v, v.sim_time_s() + 1.0);
  EXPECT_TRUE(served.truth().manual_held);
  const double along_m = (site_m(v, "wrist") - wrist0).dot(right);
  std::printf("[ info     ] target dragged %.2f mm, wrist followed %.2f mm\n",
              1e3 * dragged_m, 1e3 * along_m);
  // nothing resists but the arm's own inertia and friction: the wrist
  // follows the hand most of the way
  EXPECT_GT(along_m, 0.5 * dragged_m);
  EXPECT_LT(along_m, 1.2 * dragged_m);

  // release: the hand lets go
  v.inject(InputEvent::click(GLFW_MOUSE_BUTTON_LEFT, false, x, 240.0));
  EXPECT_FALSE(served.held());
  frames_until(&v, v.sim_time_s() + 0.1);
  EXPECT_FALSE(served.truth().manual_held);
  EXPECT_LT(served.truth().hand_force_N.norm(), 0.1);

  // the client ends: its slot is free and the server holds zero torque
  client.stop();
  frames_until(&v, v.sim_time_s() + 0.2);
  EXPECT_EQ(served.published().tau_applied_Nm, Vec3::Zero());
}

}  // namespace
}  // namespace vmh::viz
