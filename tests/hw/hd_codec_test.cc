// hw/openhaptics/hd_codec.h: every mapping between the HD API's values and
// the device layer's, with the force mode's map checked by virtual work
// against finite differences of the published OpenHaptics position formula
// (tests/support/openhaptics_reference.h), which shares no code with it.
#include "hw/openhaptics/hd_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

#include "device/device_state.h"
#include "tests/support/openhaptics_reference.h"

namespace vmh::hw::hd {
namespace {

TEST(HdCodec, TorqueUnitsAreMilliNewtonMetres) {
  const Vec3 mNm = torque_Nm_to_mNm(Vec3(0.1, -0.35, 0.002));
  EXPECT_DOUBLE_EQ(mNm[0], 100.0);
  EXPECT_DOUBLE_EQ(mNm[1], -350.0);
  EXPECT_DOUBLE_EQ(mNm[2], 2.0);
  const Vec3 back = torque_mNm_to_Nm(mNm);
  EXPECT_DOUBLE_EQ(back[0], 0.1);
  EXPECT_DOUBLE_EQ(back[1], -0.35);
  EXPECT_DOUBLE_EQ(back[2], 0.002);
}

TEST(HdCodec, TransformIsColumnMajor) {
  // a pose written out by columns: rotation 90 deg about z, then the
  // translation (10, 20, 30) mm in the fourth column
  const double hd[16] = {0, 1, 0, 0,   -1, 0, 0, 0,
                         0, 0, 1, 0,   10, 20, 30, 1};
  const Eigen::Matrix4d T = transform_from_hd(hd);
  EXPECT_EQ(T(0, 3), 10.0);
  EXPECT_EQ(T(1, 3), 20.0);
  EXPECT_EQ(T(2, 3), 30.0);
  EXPECT_EQ(T(3, 3), 1.0);
  EXPECT_EQ(T(3, 0), 0.0);
  // x axis of the rotated frame is the device's y
  EXPECT_EQ(T(1, 0), 1.0);
  EXPECT_EQ(T(0, 1), -1.0);
  const double det = T.topLeftCorner<3, 3>().determinant();
  EXPECT_NEAR(det, 1.0, 1e-15);
  double seq[16];
  for (int i = 0; i < 16; ++i) seq[i] = i;
  const Eigen::Matrix4d S = transform_from_hd(seq);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_EQ(S(r, c), c * 4 + r);
  }
}

TEST(HdCodec, ButtonBits) {
  EXPECT_EQ(buttons_from_hd(0), 0u);
  EXPECT_EQ(buttons_from_hd(1), kButton1);
  EXPECT_EQ(buttons_from_hd(2), kButton2);
  EXPECT_EQ(buttons_from_hd(3), kButton1 | kButton2);
  EXPECT_EQ(buttons_from_hd(0xFC), 0u);  // bits beyond the two buttons
}

TEST(HdCodec, InkwellReadsZeroWhileDocked) {
  EXPECT_TRUE(docked_from_hd(0));
  EXPECT_FALSE(docked_from_hd(1));
  EXPECT_FALSE(docked_from_hd(255));
}

TEST(HdCodec, WarningsKeepTheDeviceGoing) {
  for (HDerror code : {kWarmMotors, kExceededMaxForce, kExceededMaxForceImpulse,
                       kExceededMaxVelocity}) {
    const HdErrorClass c = classify_hd_error(code);
    EXPECT_FALSE(c.fatal) << hd_error_name(code);
    EXPECT_EQ(c.error, DeviceError::kOk) << hd_error_name(code);
  }
  EXPECT_EQ(hd_error_name(kWarmMotors), "warm_motors");
  EXPECT_EQ(hd_error_name(kExceededMaxForce), "exceeded_max_force");
  EXPECT_EQ(hd_error_name(kExceededMaxForceImpulse), "exceeded_max_force_impulse");
  EXPECT_EQ(hd_error_name(kExceededMaxVelocity), "exceeded_max_velocity");
  EXPECT_EQ(hd_error_name(kForceError), "force_error");
}

TEST(HdCodec, FatalErrorsMapToDeviceErrors) {
  struct Case {
    HDerror code;
    const char* name;
    DeviceError error;
  };
  const Case cases[] = {
      {kCommError, "comm_error", DeviceError::kIo},
      {kDeviceFault, "device_fault", DeviceError::kIo},
      {kCommConfigError, "comm_config_error", DeviceError::kNotConnected},
      {kTimerError, "timer_error", DeviceError::kTimeout},
      {kInvalidLicense, "invalid_license", DeviceError::kNotConnected},
      {kBadHandle, "bad_handle", DeviceError::kNotConnected},
  };
  for (const Case& c : cases) {
    const HdErrorClass k = classify_hd_error(c.code);
    EXPECT_TRUE(k.fatal) << c.name;
    EXPECT_EQ(k.error, c.error) << c.name;
    EXPECT_EQ(hd_error_name(c.code), c.name);
  }
}

TEST(HdCodec, EveryKnownCodeHasItsOwnNameAndIndex) {
  std::set<std::string> names;
  for (int i = 0; i < kHdKnownErrorCount; ++i) {
    const HDerror code = kHdKnownErrors[i];
    const HdErrorClass c = classify_hd_error(code);
    ASSERT_NE(c.name, nullptr) << std::hex << code;
    names.insert(c.name);
    EXPECT_EQ(hd_error_index(code), i);
    // a fatal error always names the device error a read reports
    EXPECT_EQ(c.fatal, c.error != DeviceError::kOk) << c.name;
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kHdKnownErrorCount));
  EXPECT_EQ(hd_error_name(kSuccess), "ok");
  EXPECT_FALSE(classify_hd_error(kSuccess).fatal);
}

TEST(HdCodec, UnknownCodesAreNamedByValueAndStopTheDevice) {
  EXPECT_EQ(hd_error_name(0x777), "hd_error_0x777");
  EXPECT_EQ(hd_error_name(0xabc), "hd_error_0xabc");
  EXPECT_EQ(classify_hd_error(0x777).name, nullptr);
  EXPECT_TRUE(classify_hd_error(0x777).fatal);
  EXPECT_EQ(hd_error_index(0x777), kHdKnownErrorCount);
}

TEST(HdCodec, CalibrationResults) {
  EXPECT_EQ(calibration_from_hd(kCalibrationOk), CalibrationState::kOk);
  EXPECT_EQ(calibration_from_hd(kCalibrationNeedsUpdate),
            CalibrationState::kNeedsUpdate);
  EXPECT_EQ(calibration_from_hd(kCalibrationNeedsManualInput),
            CalibrationState::kNeedsManualInput);
  EXPECT_EQ(calibration_from_hd(0x1234), CalibrationState::kUnknown);
  EXPECT_EQ(calibration_style_to_use(kCalibrationInkwell), kCalibrationInkwell);
  EXPECT_EQ(calibration_style_to_use(kCalibrationInkwell | kCalibrationAuto),
            kCalibrationAuto);
  EXPECT_EQ(calibration_style_to_use(kCalibrationEncoderReset | kCalibrationInkwell),
            kCalibrationInkwell);
  EXPECT_EQ(calibration_style_to_use(kCalibrationEncoderReset),
            kCalibrationEncoderReset);
  EXPECT_EQ(calibration_style_to_use(0), 0);
}

// Virtual work: the force F the map gives, moved through the displacement
// dx a small turn dt of each motor joint makes, does the work tau . dt. dx
// comes from central differences of the published position formula (mm).
TEST(HdCodec, ForceModeMapDoesTheMotorTorquesWork) {
  const OmniParams omni;
  const double l_mm = omni.l1_m * 1000.0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> t1(-0.8, 0.8), t2(-0.2, 1.2),
      t3(-0.3, 1.4), tau(-0.2, 0.2), gimbal(-1.0, 1.0);
  int checked = 0;
  for (int n = 0; n < 200; ++n) {
    Joints q;
    q << t1(rng), t2(rng), t3(rng), gimbal(rng), gimbal(rng), gimbal(rng);
    const Vec3 tau_Nm(tau(rng), tau(rng), tau(rng));
    // away from the singular poses (wrist centre on the joint-1 axis; the
    // forearm in line with the upper arm, cos(t3 - t2) = 0), where
    // J_v^T F = tau has an exact answer
    const double reach = l_mm * std::cos(q[1]) + l_mm * std::sin(q[2]);
    if (std::fabs(reach) < 30.0 || std::fabs(std::cos(q[2] - q[1])) < 0.2) {
      continue;
    }
    const Vec3 F_N = force_for_motor_torques_N(omni, q, tau_Nm);
    const double h = 1e-6;
    for (int j = 0; j < 3; ++j) {
      Joints qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      const Vec3 dx_m = (testing::openhaptics_wrist_mm(qp, l_mm, l_mm) -
                         testing::openhaptics_wrist_mm(qm, l_mm, l_mm)) /
                        (2.0 * h * 1000.0);
      EXPECT_NEAR(F_N.dot(dx_m), tau_Nm[j], 1e-6 + 1e-5 * std::fabs(tau_Nm[j]))
          << "joint " << j << " at " << q.transpose();
    }
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(HdCodec, ForceModeMapStaysFiniteAtASingularity) {
  const OmniParams omni;
  Joints q = Joints::Zero();
  q[2] = q[1] + 3.14159265358979323846 / 2.0;  // arm stretched out straight
  const Vec3 F = force_for_motor_torques_N(omni, q, Vec3(0.1, 0.1, 0.1));
  EXPECT_TRUE(F.allFinite());
  // wrist centre on the joint-1 axis: joint 1 cannot be driven by any force
  Joints q_axis = Joints::Zero();
  q_axis[1] = 0.0;
  q_axis[2] = -3.14159265358979323846 / 2.0;  // reach l1 cos t2 + l2 sin t3 = 0
  EXPECT_TRUE(force_for_motor_torques_N(omni, q_axis, Vec3(0.1, 0, 0)).allFinite());
}

}  // namespace
}  // namespace vmh::hw::hd
