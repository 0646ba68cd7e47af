// `vmhaptics hw capture`: the USB Touch's raw traffic (hw/usb/). Its `hw
// list` entry and `hw probe --device usb` are its backend's
// (hw/usb/usb_runtime.h).
#ifndef VMHAPTICS_CLI_HW_USB_H_
#define VMHAPTICS_CLI_HW_USB_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

// `hw capture --device usb[:BUS-ADDR] --duration s --out FILE [--detach]`
void register_hw_capture(CLI::App* hw);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_USB_H_
