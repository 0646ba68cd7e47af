// sim/emulator_seeded: the seeded faults' text form, and each fault's
// effect on a running emulator, against its ground truth. The emulator
// runs in lockstep (the test calls advance() once per servo period), so a
// reading and the truth of the period it shows are taken together, and a
// delay is exactly its number of periods.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "sim/sensor_model.h"

namespace vmh::sim {
namespace {

const std::string kSeededScene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";

// in lockstep
EmulatorOptions options(const std::string& seeded,
                        HandProgram hand = HandProgram::kTour) {
  EmulatorOptions o;
  o.lockstep = true;
  o.scene = kSeededScene;
  o.hand = hand;
  o.seeded = parse_seeded_faults(seeded);
  return o;
}

// n servo periods, then the reading they end with and the truth of the
// same period (its timestamp is that truth's publish time)
void run_and_read(Emulator* emu, long n, DeviceState* s, EmulatorTruth* t) {
  for (long i = 0; i < n; ++i) emu->advance();
  ASSERT_EQ(emu->read_state(s), DeviceError::kOk);
  *t = emu->truth();
  ASSERT_EQ(s->timestamp_s, t->wall_s);
}

std::string message_of(const std::string& text) {
  try {
    parse_seeded_faults(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(SeededFaults, ParseEveryKind) {
  const SeededFaults f = parse_seeded_faults(
      "joint1_sign, joint6_sign,gimbal_swap,link_length_-1.5pct,delay_5ms,"
      "motor3_relative,motor2_sign,torque_units_Nm,mass_x2,friction_x3,"
      "damping_x0.5");
  EXPECT_TRUE(f.joint_sign[0]);
  EXPECT_FALSE(f.joint_sign[1]);
  EXPECT_TRUE(f.joint_sign[5]);
  EXPECT_TRUE(f.gimbal_swap);
  EXPECT_DOUBLE_EQ(f.edit.link1_scale, 0.985);
  EXPECT_DOUBLE_EQ(f.delay_ms, 5.0);
  EXPECT_TRUE(f.edit.motor3_relative);
  EXPECT_EQ(f.edit.motor_gain, Vec3(1, -1, 1));
  EXPECT_DOUBLE_EQ(f.torque_scale, 1000.0);
  EXPECT_DOUBLE_EQ(f.edit.mass_scale, 2.0);
  EXPECT_DOUBLE_EQ(f.edit.friction_scale, 3.0);
  EXPECT_DOUBLE_EQ(f.edit.damping_scale, 0.5);
  ASSERT_EQ(f.items.size(), 11u);
  EXPECT_EQ(f.items[1], "joint6_sign");  // spaces dropped
  EXPECT_DOUBLE_EQ(parse_seeded_faults("torque_units_mNm").torque_scale, 0.001);
  EXPECT_FALSE(parse_seeded_faults("").any());
  EXPECT_TRUE(parse_seeded_faults("joint1_sign").any());
}

TEST(SeededFaults, BadItemsAreNamedWithTheKnownNames) {
  for (const std::string bad :
       {"joint7_sign", "joint0_sign", "motor4_sign", "delay_xms", "delay_-5ms",
        "mass_x0", "mass_x-1", "friction_x", "link_length_abcpct",
        "link_length_200pct", "wobble"}) {
    const std::string msg = message_of("joint1_sign," + bad);
    EXPECT_NE(msg.find("'" + bad + "'"), std::string::npos) << bad << ": " << msg;
    EXPECT_NE(msg.find("gimbal_swap"), std::string::npos) << msg;  // the list
  }
  EXPECT_NE(message_of("torque_units_Nm,torque_units_mNm").find("twice"),
            std::string::npos);
  EXPECT_NE(message_of("link_length_2pct,link_length_3pct").find("twice"),
            std::string::npos);
  EXPECT_NE(message_of("joint1_sign,,gimbal_swap").find("empty"), std::string::npos);
}

TEST(SeededFaults, ReadingsNegatedAndSwapped) {
  SeededFaults f = parse_seeded_faults("joint2_sign,gimbal_swap");
  Joints q;
  q << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  apply_seeded_readings(f, &q);
  Joints expect;
  expect << 0.1, -0.2, 0.3, 0.4, 0.6, 0.5;
  EXPECT_EQ(q, expect);
  apply_seeded_readings(SeededFaults{}, &q);
  EXPECT_EQ(q, expect);  // no faults: untouched
}

TEST(SeededFaults, DelayMustBeWholePeriods) {
  for (const std::string bad : {"delay_5.5ms", "delay_64ms"}) {
    try {
      Emulator emu(options(bad));
      FAIL() << bad;
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("delay_"), std::string::npos) << msg;
      EXPECT_NE(msg.find("servo periods"), std::string::npos) << msg;
    }
  }
  Emulator emu(options("delay_5ms"));
  EXPECT_EQ(emu.delay_periods(), 5);  // case1: 1 ms periods
}

TEST(SeededFaults, MissingModelFileIsNamed) {
  EmulatorOptions o = options("");
  o.model_file = "/nonexistent/omni.xml";
  try {
    Emulator emu(o);
    FAIL();
  } catch (const SimError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/omni.xml"), std::string::npos)
        << e.what();
  }
}

// joint1_sign and gimbal_swap: the reported angles are the sensor model's
// (factory calibration: its values to rounding) with t1 negated and t5, t6
// swapped; the raw values and the device's own transform stay true
TEST(SeededFaults, SignAndSwapChangeOnlyTheReportedAngles) {
  Emulator emu(options("joint1_sign,gimbal_swap"));
  emu.start();
  DeviceState s;
  EmulatorTruth t;
  // 0.3 s: the tour moves every joint away from zero
  ASSERT_NO_FATAL_FAILURE(run_and_read(&emu, 300, &s, &t));
  const OmniParams& p = emu.loop().controller_params().omni;
  const Joints meas = SensorModel(p, true).measure(dh_to_device_joints(t.q_end_dh));
  EXPECT_NEAR(s.q_device_rad[0], -meas[0], 1e-12);
  EXPECT_NEAR(s.q_device_rad[4], meas[5], 1e-12);
  EXPECT_NEAR(s.q_device_rad[5], meas[4], 1e-12);
  for (int i : {1, 2, 3}) EXPECT_NEAR(s.q_device_rad[i], meas[i], 1e-12) << i;
  EXPECT_GT(std::abs(meas[4] - meas[5]), 1e-3);  // the swap is visible
  EXPECT_GT(std::abs(meas[0]), 1e-3);  // the sign is visible
  // the raw values decode to the true angles
  const Joints raw = hw::angles_from_raw(s.encoder_counts, s.gimbal_pots,
                                         emu.factory_calibration());
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(raw[i], meas[i], 1e-12) << i;
  EXPECT_LE((s.transform_mm.topRightCorner<3, 1>() - t.p_end_mm).cwiseAbs().maxCoeff(),
            1e-9);
  emu.stop();
}

// delay_5ms: each reading, timestamp included, is the one published 5
// periods before the newest at the time of the read. In lockstep every
// period is read and its truth kept, so every reading is matched to its
// own truth: exactly 5 periods older (the old test, polling a running
// emulator, matched some 20 of them and allowed 4 or 5).
TEST(SeededFaults, DelayDeliversReadingsFivePeriodsOld) {
  Emulator emu(options("delay_5ms"));
  emu.start();
  const OmniParams& p = emu.loop().controller_params().omni;
  const SensorModel sensor(p, true);
  const long n = 400;
  std::vector<EmulatorTruth> truths;  // truths[k]: the truth of period k
  truths.reserve(static_cast<std::size_t>(n) + 1);
  truths.push_back(emu.truth());  // the start state, published at 0
  for (long k = 1; k <= n; ++k) {
    emu.advance();
    truths.push_back(emu.truth());
    DeviceState s;
    ASSERT_EQ(emu.read_state(&s), DeviceError::kOk) << k;
    // until there is a reading 5 periods old, the first one (the start
    // state), as a device's first readings would be
    const EmulatorTruth& shown = truths[static_cast<std::size_t>(std::max(0L, k - 5))];
    ASSERT_EQ(s.timestamp_s, shown.wall_s) << k;
    const Joints meas = sensor.measure(dh_to_device_joints(shown.q_end_dh));
    EXPECT_LE((s.q_device_rad - meas).cwiseAbs().maxCoeff(), 1e-12) << k;
    EXPECT_LE((s.transform_mm.topRightCorner<3, 1>() - shown.p_end_mm)
                  .cwiseAbs().maxCoeff(), 1e-9) << k;
  }
  emu.stop();
  // and the check tells 5 periods from none: the tour moves the stylus
  // measurably in 5 periods
  const Vec3 moved = truths[200].p_end_mm - truths[195].p_end_mm;
  EXPECT_GT(moved.norm(), 1e-3);
}

// torque_units_*: the motors hold the written torque times 1000 (clamped to
// the model's ctrlrange) or times 0.001
TEST(SeededFaults, TorqueUnitsScaleTheAppliedTorque) {
  for (const auto& [name, scale] :
       {std::pair<std::string, double>{"torque_units_Nm", 1e3},
        std::pair<std::string, double>{"torque_units_mNm", 1e-3}}) {
    EmulatorOptions o = options(name);
    o.device_watchdog_s = 0.0;
    Emulator emu(o);
    const mjModel* m = emu.loop().model();
    emu.start();
    for (const Vec3& tau : {Vec3(1e-4, -1e-4, 2e-4), Vec3(0.01, -0.01, 0.02),
                            Vec3(30.0, -20.0, 10.0)}) {
      Vec3 expect;
      for (int k = 0; k < 3; ++k) {
        const int a = mj_name2id(m, mjOBJ_ACTUATOR, kOmniMotors[k]);
        expect[k] = std::clamp(scale * tau[k], m->actuator_ctrlrange[2 * a],
                               m->actuator_ctrlrange[2 * a + 1]);
      }
      ASSERT_EQ(emu.write_motor_torques(tau), DeviceError::kOk);
      // held over the very next period (the old test polled for up to 2 s)
      emu.advance();
      const bool held = (emu.truth().motor_torque_Nm - expect).norm() < 1e-12;
      EXPECT_TRUE(held) << name << " tau " << tau.transpose() << ": holds "
                        << emu.truth().motor_torque_Nm.transpose() << ", expected "
                        << expect.transpose();
    }
    emu.stop();
  }
}

// link_length_2pct: the transform is omni_fk with l1 2 % longer
TEST(SeededFaults, LongerLinkMovesTheReportedTransform) {
  Emulator emu(options("link_length_2pct"));
  emu.start();
  DeviceState s;
  EmulatorTruth t;
  ASSERT_NO_FATAL_FAILURE(run_and_read(&emu, 200, &s, &t));
  emu.stop();
  const OmniParams& nominal = emu.loop().controller_params().omni;
  OmniParams longer = nominal;
  longer.l1_m *= 1.02;
  const Vec3 p = s.transform_mm.topRightCorner<3, 1>();
  EXPECT_LE((p - base_to_device_mm(nominal, omni_fk(longer, t.q_end_dh).p_base_m))
                .cwiseAbs().maxCoeff(), 1e-9);
  // 2 % of 133 mm: the nominal FK is millimetres off
  EXPECT_GT((p - base_to_device_mm(nominal, omni_fk(nominal, t.q_end_dh).p_base_m))
                .norm(), 2.0);
}

// the parameter faults reach the emulator's model
TEST(SeededFaults, ModelFaultsEditTheEmulatorsModel) {
  Emulator emu(options("motor1_sign,motor3_relative,mass_x2,friction_x3,damping_x0.5"));
  ClosedLoop plain(kSeededScene, {});
  const mjModel* a = emu.loop().model();
  const mjModel* b = plain.model();
  const int m1 = mj_name2id(a, mjOBJ_ACTUATOR, "m1");
  EXPECT_EQ(a->actuator_gear[6 * m1], -b->actuator_gear[6 * m1]);
  const int upper = mj_name2id(a, mjOBJ_BODY, "upper_arm");
  EXPECT_DOUBLE_EQ(a->body_mass[upper], 2 * b->body_mass[upper]);
  const int q2 = a->jnt_dofadr[mj_name2id(a, mjOBJ_JOINT, "q2")];
  EXPECT_DOUBLE_EQ(a->dof_frictionloss[q2], 3 * b->dof_frictionloss[q2]);
  EXPECT_DOUBLE_EQ(a->dof_damping[q2], 0.5 * b->dof_damping[q2]);
  EXPECT_GT(b->dof_frictionloss[q2], 0.0);
  EXPECT_GT(b->dof_damping[q2], 0.0);
  // motor 3 relative: its tendon no longer couples q2
  const int t3 = mj_name2id(a, mjOBJ_TENDON, "t3");
  const int jq2 = mj_name2id(a, mjOBJ_JOINT, "q2");
  double coef_a = 0, coef_b = 0;
  for (int w = a->tendon_adr[t3]; w < a->tendon_adr[t3] + a->tendon_num[t3]; ++w) {
    if (a->wrap_objid[w] == jq2) coef_a = a->wrap_prm[w];
    if (b->wrap_objid[w] == jq2) coef_b = b->wrap_prm[w];
  }
  EXPECT_EQ(coef_a, 0.0);
  EXPECT_NE(coef_b, 0.0);
}

}  // namespace
}  // namespace vmh::sim
