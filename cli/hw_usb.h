// The USB Touch on the command line (hw/usb/): its entry in `hw list`,
// `hw probe --device usb[:BUS-ADDR]` and `hw capture`. Nothing is decoded:
// the Touch's payload protocol is not public (hw/usb/README.md).
#ifndef VMHAPTICS_CLI_HW_USB_H_
#define VMHAPTICS_CLI_HW_USB_H_

#include <CLI/CLI.hpp>
#include <string>

#include "cli/json_util.h"

namespace vmh::cli {

// the "usb_touch" entry of `hw list`: the Touches libusb finds, whether
// each can be opened, and why not
Json usb_touch_backend_json();

// `hw probe --device usb[:BUS-ADDR]`: the descriptors, strings and kernel
// drivers of the Touch, as JSON on stdout. `argument` is what follows
// "usb:" (empty: the first Touch). UsageError (exit 2) for a bad BUS-ADDR,
// no such device or no Touch.
void usb_probe(const std::string& argument);

// `hw capture --device usb[:BUS-ADDR] --duration s --out FILE [--detach]`
void register_hw_capture(CLI::App* hw);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_USB_H_
