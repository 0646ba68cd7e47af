// sim/sim_device: the MuJoCo Omni behind the device interface. Readings are
// the model's DH joint angles in the device convention, through the sensor
// model; writes are clamped to each motor's ctrlrange, delayed by whole
// servo ticks, and land in d->ctrl.
//
// The reference values come from the model by their own route: joint
// angles through jnt_qposadr by name, motor limits from actuator_ctrlrange
// by name, and the device convention written out by hand (t1 = -q1,
// t2 = q2, t3 = q2 + q3, t4 = -q4, t5 = q5, t6 = -q6).
#include "sim/sim_device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "sim/mujoco_util.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/temp_mjcf.h"
#include "tests/support/constants.h"

namespace vmh::sim {
namespace {

using vmh::testing::kPi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string case1() { return std::string(VMH_MODELS_DIR) + "/cases/case1.xml"; }

int joint_qposadr(const mjModel* m, const char* name) {
  const int j = mj_name2id(m, mjOBJ_JOINT, name);
  EXPECT_GE(j, 0) << name;
  return j < 0 ? 0 : m->jnt_qposadr[j];
}

int actuator_id(const mjModel* m, const char* name) {
  const int a = mj_name2id(m, mjOBJ_ACTUATOR, name);
  EXPECT_GE(a, 0) << name;
  return a < 0 ? 0 : a;
}

void set_dh(const mjModel* m, mjData* d, const Joints& q_dh) {
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    d->qpos[joint_qposadr(m, name.c_str())] = q_dh[i];
  }
}

// the device convention, by hand
Joints device_of(const Joints& q) {
  Joints t;
  t << -q[0], q[1], q[1] + q[2], -q[3], q[4], -q[5];
  return t;
}

// the motors' torques in d->ctrl, read by actuator name
Vec3 ctrl_of(const mjModel* m, const mjData* d) {
  return Vec3(d->ctrl[actuator_id(m, "m1")], d->ctrl[actuator_id(m, "m2")],
              d->ctrl[actuator_id(m, "m3")]);
}

class SimDeviceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = load_model(case1());
    data_.reset(mj_makeData(model_.get()));
  }
  const mjModel* m() const { return model_.get(); }
  mjData* d() { return data_.get(); }

  testing::MujocoGuard guard_;
  ModelPtr model_;
  DataPtr data_;
  OmniParams omni_;
};

TEST_F(SimDeviceTest, ReadsTheModelAnglesInTheDeviceConvention) {
  SimDevice dev(m(), d(), omni_, /*quantize=*/false, 0, case1());
  Joints q_dh;
  q_dh << 0.3, -0.2, 0.5, 1.0, -0.7, 2.0;
  set_dh(m(), d(), q_dh);
  Joints t;
  ASSERT_EQ(dev.read_joints(&t), DeviceError::kOk);
  const Joints expected = device_of(q_dh);  // (-0.3, -0.2, 0.3, -1, -0.7, -2)
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(t[i], expected[i]) << i;
  EXPECT_EQ(dev.true_q_dh(), q_dh);
}

// With the sensors on, each reading is within half a step of the truth:
// pi / 15000 rad for t1..t3 and range / 2^12 for t4..t6.
TEST_F(SimDeviceTest, QuantisedReadingsAreWithinHalfAStep) {
  SimDevice dev(m(), d(), omni_, /*quantize=*/true, 0, case1());
  const double half_rad[6] = {kPi / 15000.0, kPi / 15000.0, kPi / 15000.0,
                              4.90 / 4096.0, 2.26 / 4096.0, 5.16 / 4096.0};
  const Joints samples[] = {
      (Joints() << 0.3, -0.2, 0.5, 1.0, -0.7, 2.0).finished(),
      (Joints() << -0.81, 1.2, -0.6, -2.2, 1.05, -0.01).finished(),
      (Joints() << 1e-5, 2e-5, -3e-5, 4e-4, -5e-4, 6e-4).finished()};
  bool any_change = false;
  for (const Joints& q_dh : samples) {
    set_dh(m(), d(), q_dh);
    Joints t;
    ASSERT_EQ(dev.read_joints(&t), DeviceError::kOk);
    const Joints expected = device_of(q_dh);
    for (int i = 0; i < 6; ++i) {
      EXPECT_LE(std::abs(t[i] - expected[i]), half_rad[i] * (1 + 1e-9)) << i;
      any_change = any_change || t[i] != expected[i];
    }
  }
  EXPECT_TRUE(any_change) << "quantisation left every reading exact";
}

TEST_F(SimDeviceTest, NonFiniteJointIsASensorFault) {
  SimDevice dev(m(), d(), omni_, true, 0, case1());
  d()->qpos[joint_qposadr(m(), "q5")] = kNaN;
  Joints t;
  EXPECT_EQ(dev.read_joints(&t), DeviceError::kSensorFault);
}

TEST_F(SimDeviceTest, WritesAreClampedToEachMotorsCtrlrange) {
  SimDevice dev(m(), d(), omni_, false, 0, case1());
  double lo[3], hi[3];
  const char* names[3] = {"m1", "m2", "m3"};
  for (int i = 0; i < 3; ++i) {
    const int a = actuator_id(m(), names[i]);
    ASSERT_TRUE(m()->actuator_ctrllimited[a]) << names[i];
    lo[i] = m()->actuator_ctrlrange[2 * a];
    hi[i] = m()->actuator_ctrlrange[2 * a + 1];
  }
  // above, below and inside the ranges
  EXPECT_EQ(dev.write_motor_torques(Vec3(5.0, -5.0, 0.01)), DeviceError::kOk);
  EXPECT_TRUE(dev.clamped());
  EXPECT_EQ(ctrl_of(m(), d()), Vec3(hi[0], lo[1], 0.01));
  EXPECT_EQ(dev.motor_torque_Nm(), ctrl_of(m(), d()));

  EXPECT_EQ(dev.write_motor_torques(Vec3(-0.5, 0.5, -1.0)), DeviceError::kOk);
  EXPECT_TRUE(dev.clamped());
  EXPECT_EQ(ctrl_of(m(), d()), Vec3(lo[0], hi[1], lo[2]));

  // inside: passed through, and the clamp flag drops again
  const Vec3 inside(0.5 * hi[0], 0.5 * lo[1], 0.9 * hi[2]);
  EXPECT_EQ(dev.write_motor_torques(inside), DeviceError::kOk);
  EXPECT_FALSE(dev.clamped());
  EXPECT_EQ(ctrl_of(m(), d()), inside);
}

// A torque written at write k is in d->ctrl after write k + n, and zero is
// held there until the first one arrives.
TEST_F(SimDeviceTest, DelayLineShiftsByWholeWrites) {
  for (const int n : {0, 1, 3, kMaxDelayTicks}) {
    SimDevice dev(m(), d(), omni_, false, n, case1());
    auto command = [](int k) {
      return Vec3(1e-3 * (k + 1), -1e-3 * (k + 2), 5e-4 * (k % 7));
    };
    for (int k = 0; k < n + 40; ++k) {
      ASSERT_EQ(dev.write_motor_torques(command(k)), DeviceError::kOk);
      const Vec3 expected = k < n ? Vec3::Zero() : command(k - n);
      ASSERT_EQ(ctrl_of(m(), d()), expected) << "delay " << n << " write " << k;
    }
  }
}

TEST_F(SimDeviceTest, NonFiniteTorqueWritesZeroAndSaysSo) {
  SimDevice dev(m(), d(), omni_, false, 0, case1());
  ASSERT_EQ(dev.write_motor_torques(Vec3(0.1, 0.1, 0.1)), DeviceError::kOk);
  for (const Vec3& bad :
       {Vec3(kNaN, 0.1, 0.1),
        Vec3(0.1, std::numeric_limits<double>::infinity(), 0.1),
        Vec3(0.05, 0.05, -std::numeric_limits<double>::infinity())}) {
    EXPECT_EQ(dev.write_motor_torques(bad), DeviceError::kInvalidCommand);
    EXPECT_EQ(ctrl_of(m(), d()), Vec3::Zero()) << bad.transpose();
    EXPECT_FALSE(dev.clamped());
    ASSERT_EQ(dev.write_motor_torques(Vec3(0.1, 0.1, 0.1)), DeviceError::kOk);
  }
}

// reset() drops the commands waiting in the delay line and zeroes the motors
TEST_F(SimDeviceTest, ResetEmptiesTheDelayLine) {
  SimDevice dev(m(), d(), omni_, false, 2, case1());
  const Vec3 a(0.01, 0.02, 0.03), b(0.04, 0.05, 0.06), c(-0.01, -0.02, -0.03);
  dev.write_motor_torques(a);
  dev.write_motor_torques(b);
  dev.write_motor_torques(b);  // a reaches the motors
  ASSERT_EQ(ctrl_of(m(), d()), a);
  dev.reset();
  EXPECT_EQ(ctrl_of(m(), d()), Vec3::Zero());
  dev.write_motor_torques(c);
  EXPECT_EQ(ctrl_of(m(), d()), Vec3::Zero()) << "b was still queued";
  dev.write_motor_torques(c);
  EXPECT_EQ(ctrl_of(m(), d()), Vec3::Zero()) << "b was still queued";
  dev.write_motor_torques(c);
  EXPECT_EQ(ctrl_of(m(), d()), c);
}

TEST_F(SimDeviceTest, DelayOutOfRangeIsRefused) {
  for (const int n : {-1, kMaxDelayTicks + 1}) {
    try {
      SimDevice dev(m(), d(), omni_, false, n, case1());
      ADD_FAILURE() << "delay " << n << " accepted";
    } catch (const SimError& e) {
      EXPECT_NE(std::string(e.what()).find("delay_ticks"), std::string::npos)
          << e.what();
    }
  }
}

// ---- hand-made scenes: missing pieces, other layouts --------------------

struct ChainOptions {
  bool with_q4 = true;
  bool q5_is_slide = false;
  bool with_m2 = true;
  bool ctrl_limited = true;
  bool extra_joint_first = false;  // a slide joint ahead of q1 in qpos
};

// six bodies in a chain, a joint "q<i>" in each, motors "m1".."m3" on the
// first three joints; no geometry, so nothing collides
std::string chain_scene(const ChainOptions& o) {
  const std::string inertial =
      "<inertial pos=\"0 0 0\" mass=\"0.05\" diaginertia=\"1e-5 1e-5 1e-5\"/>";
  std::string xml =
      "<mujoco model=\"chain\">\n<compiler autolimits=\"true\"/>\n"
      "<worldbody>\n";
  if (o.extra_joint_first) {
    xml += "<body name=\"extra\" pos=\"1 0 0\">" + inertial +
           "<joint name=\"extra\" type=\"slide\" axis=\"1 0 0\"/></body>\n";
  }
  for (int i = 1; i <= 6; ++i) {
    xml += "<body name=\"b" + std::to_string(i) + "\" pos=\"0 0 0.05\">" +
           inertial;
    if (i == 4 && !o.with_q4) {
      // no joint: the body is welded to its parent
    } else if (i == 5 && o.q5_is_slide) {
      xml += "<joint name=\"q5\" type=\"slide\" axis=\"0 0 1\"/>";
    } else {
      xml += "<joint name=\"q" + std::to_string(i) +
             "\" type=\"hinge\" axis=\"0 1 0\"/>";
    }
    xml += "\n";
  }
  for (int i = 0; i < 6; ++i) xml += "</body>";
  xml += "\n</worldbody>\n<actuator>\n";
  for (int i = 1; i <= 3; ++i) {
    if (i == 2 && !o.with_m2) continue;
    xml += "<motor name=\"m" + std::to_string(i) + "\" joint=\"q" +
           std::to_string(i) + "\"" +
           (o.ctrl_limited ? " ctrlrange=\"-0.1 0.1\"" : "") + "/>\n";
  }
  xml += "</actuator>\n</mujoco>\n";
  return xml;
}

class ChainSceneTest : public ::testing::Test {
 protected:
  // the SimError message of building a device on the scene ("" if none)
  std::string device_error(const ChainOptions& o) {
    path_ = dir_.write("chain.xml", chain_scene(o));
    ModelPtr m = load_model(path_);
    DataPtr d(mj_makeData(m.get()));
    try {
      SimDevice dev(m.get(), d.get(), OmniParams(), false, 0, path_);
    } catch (const SimError& e) {
      return e.what();
    }
    return "";
  }

  testing::MujocoGuard guard_;
  testing::TempMjcfDir dir_;
  std::string path_;
};

TEST_F(ChainSceneTest, TheFullChainIsAccepted) {
  EXPECT_EQ(device_error(ChainOptions()), "");
}

TEST_F(ChainSceneTest, MissingActuatorIsNamed) {
  ChainOptions o;
  o.with_m2 = false;
  const std::string msg = device_error(o);
  EXPECT_NE(msg.find("actuator 'm2'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path_), std::string::npos) << msg;
}

TEST_F(ChainSceneTest, MissingJointIsNamed) {
  ChainOptions o;
  o.with_q4 = false;
  const std::string msg = device_error(o);
  EXPECT_NE(msg.find("joint 'q4'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path_), std::string::npos) << msg;
}

TEST_F(ChainSceneTest, NonHingeJointIsNamed) {
  ChainOptions o;
  o.q5_is_slide = true;
  const std::string msg = device_error(o);
  EXPECT_NE(msg.find("'q5'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("hinge"), std::string::npos) << msg;
}

// Joints are found by name, not by position in qpos.
TEST_F(ChainSceneTest, ReadsJointsByName) {
  ChainOptions o;
  o.extra_joint_first = true;
  path_ = dir_.write("chain.xml", chain_scene(o));
  ModelPtr m = load_model(path_);
  DataPtr d(mj_makeData(m.get()));
  ASSERT_EQ(m->nq, 7);
  ASSERT_NE(joint_qposadr(m.get(), "q1"), 0);
  SimDevice dev(m.get(), d.get(), OmniParams(), false, 0, path_);
  Joints q_dh;
  q_dh << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  d->qpos[joint_qposadr(m.get(), "extra")] = 9.0;
  set_dh(m.get(), d.get(), q_dh);
  Joints t;
  ASSERT_EQ(dev.read_joints(&t), DeviceError::kOk);
  const Joints expected = device_of(q_dh);
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(t[i], expected[i]) << i;
}

// Motors without a ctrlrange are clamped to OmniParams' limits instead.
TEST_F(ChainSceneTest, UnlimitedMotorsFallBackOnTheOmniLimits) {
  ChainOptions o;
  o.ctrl_limited = false;
  path_ = dir_.write("chain.xml", chain_scene(o));
  ModelPtr m = load_model(path_);
  DataPtr d(mj_makeData(m.get()));
  ASSERT_FALSE(m->actuator_ctrllimited[actuator_id(m.get(), "m1")]);
  const OmniParams omni;
  SimDevice dev(m.get(), d.get(), omni, false, 0, path_);
  dev.write_motor_torques(Vec3(1.0, -1.0, 1.0));
  EXPECT_TRUE(dev.clamped());
  EXPECT_EQ(ctrl_of(m.get(), d.get()),
            Vec3(omni.motor_torque_limit_Nm[0], -omni.motor_torque_limit_Nm[1],
                 omni.motor_torque_limit_Nm[2]));
  // 200, 350 and 200 mN m (OpenHaptics' clamps)
  EXPECT_EQ(ctrl_of(m.get(), d.get()), Vec3(0.2, -0.35, 0.2));
}

}  // namespace
}  // namespace vmh::sim
