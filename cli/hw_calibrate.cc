// vmhaptics hw calibrate [--device D] [--dock-s s] [--sweep-s s]
//
// The joint-angle calibration of a device (runtime/calibrate.h: the
// procedure, the checks, the store); this file parses, calls and prints.
// Exit codes as the other hw verbs, and 1 when the fit is refused (the
// message names the joint and what to redo; nothing is stored).
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/hw.h"
#include "cli/hw_common.h"
#include "runtime/calibrate.h"

namespace vmh::cli {
namespace {

struct CalibrateArgs {
  HwCommon common;
  double dock_s = 6.0;
  double sweep_s = 10.0;
};

void calibrate(const CalibrateArgs& a) {
  check_seconds("hw calibrate: --dock-s", a.dock_s, 1.0, 600.0);
  check_seconds("hw calibrate: --sweep-s", a.sweep_s, 1.0, 600.0);
  HwCommon c = a.common;
  c.no_calibration = true;  // fit from the raw readings alone
  runtime::OpenedDevice dev = open_hw_device(c, "dock");
  runtime::CalibrateOptions o;
  o.dock_s = a.dock_s;
  o.sweep_s = a.sweep_s;
  const runtime::SessionOptions so = session_options(c, "calibrate");
  o.servo = so.servo;
  o.progress = so.progress;
  Json out;
  try {
    out = runtime::calibrate(&dev, o);
  } catch (const runtime::CalibrationError& e) {
    throw std::runtime_error(std::string("hw calibrate: ") + e.what());
  }
  std::cout << dump_readable(out) << '\n';
}

}  // namespace

void register_hw_calibrate(CLI::App* hw) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = hw->add_subcommand(
      "calibrate",
      "inkwell calibration (encoder offsets) and the gimbal potentiometers' "
      "two-point fit, checked and stored per serial number under "
      "$XDG_CONFIG_HOME/vmhaptics/calibration/");
  add_hw_common(cmd, &a->common);
  cmd->add_option("--dock-s", a->dock_s,
                  "seconds for the inkwell phase, > 1 and <= 600 (default 6)");
  cmd->add_option("--sweep-s", a->sweep_s,
                  "seconds for the gimbal sweep, > 1 and <= 600 (default 10)");
  cmd->callback([a]() { calibrate(*a); });
}

}  // namespace vmh::cli
