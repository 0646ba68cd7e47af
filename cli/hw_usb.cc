// vmhaptics hw capture --device usb[:BUS-ADDR] --duration s --out FILE [--detach]
// (the USB Touch's listing and probe are its backend's:
// hw/usb/usb_runtime.h)
//
// Exit codes: 0 done; 2 bad usage, no such device, or a device that cannot
// be opened or claimed (nothing written); 1 the device failed during the
// capture (an unplug: the file keeps every transfer and ends with
// "# error: ...").
#include "cli/hw_usb.h"

#include <cmath>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/hw_common.h"
#include "hw/usb/usb_runtime.h"

namespace vmh::cli {
namespace {

namespace usb = vmh::hw::usb;

struct CaptureArgs {
  std::string device = "usb";
  double duration_s = std::nan("");
  std::string out;
  bool detach = false;
};

void capture(const CaptureArgs& a) {
  const auto colon = a.device.find(':');
  if (a.device.substr(0, colon) != "usb") {
    throw UsageError("--device " + a.device + ": this verb takes usb[:BUS-ADDR] only");
  }
  usb::CaptureOptions o;
  o.where = usb::parse_where(colon == std::string::npos
                                 ? std::string()
                                 : a.device.substr(colon + 1));
  check_seconds("hw capture: --duration", a.duration_s, 0.0, 3600.0);
  o.duration_s = a.duration_s;
  o.out_path = a.out;
  o.detach = a.detach;
  usb::CaptureResult r;
  try {
    r = usb::capture_touch(o);
  } catch (const usb::UsbUsageError& e) {
    throw UsageError(std::string("hw capture: ") + e.what());
  } catch (const usb::UsbDeviceError& e) {
    throw UsageError(std::string("hw capture: ") + e.what());
  }
  std::cout << dump_readable(usb::capture_json(r)) << '\n';
  if (!r.error.empty()) {
    throw std::runtime_error("hw capture: " + r.error + "; " + std::to_string(r.transfers) +
                             " transfers kept in " + r.out_path);
  }
}

}  // namespace

void register_hw_capture(CLI::App* hw) {
  auto a = std::make_shared<CaptureArgs>();
  CLI::App* c = hw->add_subcommand(
      "capture",
      "the USB Touch's raw IN transfers, timestamped, to a text file; nothing "
      "decoded (hw/usb/README.md)");
  c->add_option("--device", a->device, "usb[:BUS-ADDR] (default: the first Touch)");
  c->add_option("--duration", a->duration_s, "seconds to capture, > 0 and <= 3600")->required();
  c->add_option("--out", a->out, "the capture file (hw/usb/README.md, capture format)")
      ->required();
  c->add_flag("--detach", a->detach,
              "detach the kernel driver (cdc_acm) from the data interface for "
              "the capture; it is re-attached afterwards");
  c->callback([a]() { capture(*a); });
}

}  // namespace vmh::cli
