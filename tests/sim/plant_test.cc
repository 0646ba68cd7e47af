// sim/plant: the passivity observer against the work of a constant torque
// in closed form, and a bad state caught, named and cleared by reset().
//
// The scene is one hinge with a motor and nothing else (no gravity, no
// damping, no limits), so the motor's work over any motion is tau times
// the angle turned, and the kinetic energy is what that work gave it (to
// the integrator's error).
#include "sim/plant.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "tests/support/mujoco_guard.h"
#include "tests/support/temp_mjcf.h"

namespace vmh::sim {
namespace {

constexpr double kTorque_Nm = 0.02;

const char* kHinge = R"(<mujoco model="hinge">
  <option timestep="0.001" integrator="Euler" gravity="0 0 0"/>
  <worldbody>
    <body name="bar">
      <joint name="h" type="hinge" axis="0 0 1"/>
      <geom type="box" size="0.1 0.01 0.01" mass="0.3"/>
    </body>
  </worldbody>
  <actuator><motor joint="h" gear="1"/></actuator>
</mujoco>)";

class PlantTest : public ::testing::Test {
 protected:
  Plant make() {
    Plant p(load_model(dir_.write("hinge.xml", kHinge)), "hinge.xml");
    p.make_data();
    p.reset();
    return p;
  }
  testing::MujocoGuard guard_;
  testing::TempMjcfDir dir_;
};

TEST_F(PlantTest, MotorWorkIsTorqueTimesTheAngleTurned) {
  Plant p = make();
  p.data()->ctrl[0] = kTorque_Nm;
  ASSERT_TRUE(p.step(500, 0.0));
  const double angle_rad = p.data()->qpos[0];
  EXPECT_GT(angle_rad, 0.01);  // it turned
  EXPECT_NEAR(p.energy_motor_J(), kTorque_Nm * angle_rad, 1e-15);
  EXPECT_EQ(p.energy_hand_J(), 0.0);  // nothing applied
  // the work went into motion, to Euler's error over 500 steps
  EXPECT_NEAR(p.kinetic_J(), p.energy_motor_J(), 0.01 * p.energy_motor_J());
  EXPECT_TRUE(p.state_finite());
  EXPECT_FALSE(p.physics_fault().has_value());
  EXPECT_NO_THROW(p.throw_if_physics_fault());
  EXPECT_NEAR(p.data()->time, 0.5, 1e-12);
}

TEST_F(PlantTest, ABadStateIsCaughtNamedAndClearedByReset) {
  Plant p = make();
  ASSERT_TRUE(p.step(10, 0.0));
  p.data()->qvel[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(p.step(1, 0.25));
  ASSERT_TRUE(p.physics_fault().has_value());
  EXPECT_NEAR(p.physics_fault()->t_s, 0.251, 1e-12);  // the step's end
  EXPECT_EQ(p.physics_fault()->part, "qvel");
  EXPECT_GT(p.warning_counts()[mjWARN_BADQVEL], 0);
  try {
    p.throw_if_physics_fault();
    ADD_FAILURE() << "no PhysicsError";
  } catch (const PhysicsError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("hinge.xml"), std::string::npos) << msg;
    EXPECT_NE(msg.find("t=0.251 s (qvel"), std::string::npos) << msg;
  }
  p.reset();
  EXPECT_FALSE(p.physics_fault().has_value());
  EXPECT_EQ(p.warning_counts()[mjWARN_BADQVEL], 0);
  EXPECT_EQ(p.energy_motor_J(), 0.0);
  EXPECT_TRUE(p.step(5, 0.0));
}

}  // namespace
}  // namespace vmh::sim
