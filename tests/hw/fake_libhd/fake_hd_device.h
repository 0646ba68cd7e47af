// The device model behind the test libHD.so (fake_libhd.cc): the one seam
// where a device is made from the configuration name hdInitDevice was given.
#ifndef VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_DEVICE_H_
#define VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_DEVICE_H_

#include <memory>
#include <string>

#include "device/haptic_device.h"

namespace vmh::fake_hd {

// A running device in the device convention (t1..t6 rad, t3 absolute; motor
// torques N m). `config` holds the configuration's comma-separated tokens
// the library itself does not handle ("docked", "button1", "button2"); an
// unknown one throws std::invalid_argument naming it. The device runs in
// real time from its creation.
std::unique_ptr<HapticDevice> fake_hd_make_device(const std::string& config);

}  // namespace vmh::fake_hd

#endif  // VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_DEVICE_H_
