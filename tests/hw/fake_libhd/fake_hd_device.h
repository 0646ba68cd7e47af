// The device model behind the test libHD.so (fake_libhd.cc): the one seam
// where a device is made from the configuration name hdInitDevice was given.
#ifndef VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_DEVICE_H_
#define VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_DEVICE_H_

#include <cstdint>
#include <memory>
#include <string>

#include "controller/types.h"
#include "device/haptic_device.h"

namespace vmh::fake_hd {

// A running device in the device convention (t1..t6 rad, t3 absolute; motor
// torques N m). `config` holds the configuration's comma-separated tokens
// the library itself does not handle ("docked", "button1", "button2"); an
// unknown one throws std::invalid_argument naming it. The device runs in
// real time from its creation.
//
// Two implementations, chosen by the build: over the MuJoCo emulator
// (fake_hd_emulator_device.cc, nobody holding the stylus, or the "tour"
// token for the scripted hand) when the testbed is built, and a small rigid
// model (fake_hd_device.cc) in a build without MuJoCo.
std::unique_ptr<HapticDevice> fake_hd_make_device(const std::string& config);

// The configuration tokens the device model takes: "docked", "button1",
// "button2" force the switches; "tour" has the emulator's scripted hand move
// the stylus. Throws std::invalid_argument naming an unknown token.
struct ModelTokens {
  bool docked = false;
  std::uint32_t buttons = 0;
  bool tour = false;
};
ModelTokens parse_model_tokens(const std::string& config);

// The model's own joint angles, DH convention (rad), independent of the
// sensor path: the emulator's MuJoCo state. false for a model that has none.
bool fake_hd_true_q_dh(const HapticDevice& device, Joints* q_dh_rad);

}  // namespace vmh::fake_hd

#endif  // VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_DEVICE_H_
