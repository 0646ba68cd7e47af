#include "cli/hw_backends.h"

#include <dirent.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "cli/args.h"
#include "cli/hw_calibration_store.h"
#include "cli/hw_usb.h"
#include "device/servo_thread.h"
#include "hw/openhaptics/hd_library.h"
#include "hw/openhaptics/openhaptics_backend.h"
#include "sim/emulator.h"
#include "sim/mujoco_util.h"
#include "studies/run_case.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;

// The emulator behind DeviceBackend: its physics thread, and the project's
// own servo thread driving the loop, as a native driver will.
class EmulatorBackend final : public DeviceBackend {
 public:
  explicit EmulatorBackend(const sim::EmulatorOptions& o) : emu_(o) {}
  ~EmulatorBackend() override { stop(); }

  DeviceIdentity identity() const override { return emu_.identity(); }
  CalibrationState calibration_state() override { return CalibrationState::kOk; }
  HapticDevice* device() noexcept override { return &emu_; }

  ServoReport start(ServoLoop* loop, const ServoOptions& options) override {
    emu_.start();
    thread_ = std::make_unique<ServoThread>(loop, options);
    return thread_->start();
  }
  void stop() noexcept override {
    if (thread_) thread_->stop();
    (void)emu_.write_motor_torques(Vec3::Zero());
    emu_.stop();
  }
  bool running() const noexcept override {
    return thread_ != nullptr && thread_->running();
  }
  TickStats timing() const override {
    return thread_ ? thread_->timing() : TickStats{};
  }

  sim::Emulator* emulator() { return &emu_; }

 private:
  sim::Emulator emu_;
  std::unique_ptr<ServoThread> thread_;
};

sim::HandProgram hand_program(const std::string& name) {
  if (name == "case") return sim::HandProgram::kCase;
  if (name == "tour") return sim::HandProgram::kTour;
  if (name == "none") return sim::HandProgram::kNone;
  if (name == "dock") return sim::HandProgram::kDock;
  if (name == "gimbal_sweep") return sim::HandProgram::kGimbalSweep;
  throw UsageError("--hand: unknown '" + name +
                   "' (expected case, tour, none, dock or gimbal_sweep)");
}

OpenedDevice open_emulator(const DeviceSpec& spec, const OpenOptions& oo) {
  sim::EmulatorOptions eo;
  std::string name;
  try {
    eo.scene = studies::resolve_scene(spec.argument.empty() ? "case1" : spec.argument,
                                      &name);
    eo.faults = sim::parse_emulator_faults(oo.faults);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--device emulator: ") + e.what());
  }
  try {
    eo.seeded = sim::parse_seeded_faults(oo.seeded);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--emulator-fault: ") + e.what());
  }
  if (!oo.model_file.empty()) {
    std::error_code ec;
    if (!fs::is_regular_file(oo.model_file, ec)) {
      throw UsageError("--model: no such file '" + oo.model_file + "'");
    }
    eo.model_file = fs::absolute(oo.model_file, ec).string();
  }
  eo.overrides = oo.overrides;
  eo.hand = hand_program(oo.hand);
  std::unique_ptr<EmulatorBackend> backend;
  try {
    backend = std::make_unique<EmulatorBackend>(eo);
  } catch (const sim::SimError& e) {
    // a bad scene or --model file, named in the message
    throw UsageError(std::string("--device emulator: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--device emulator: ") + e.what());
  }
  OpenedDevice dev;
  dev.emulator = backend->emulator();
  std::error_code ec;
  dev.scene = fs::absolute(eo.scene, ec).string();
  dev.hand = oo.hand;
  dev.model_file = eo.model_file;
  dev.seeded_faults = eo.seeded.items;
  dev.calibration_source = "factory (the emulator's own)";
  if (oo.load_calibration) {
    std::optional<StoredCalibration> stored;
    try {
      stored = load_calibration(backend->identity().serial);
    } catch (const std::runtime_error& e) {
      throw UsageError(std::string("stored calibration: ") + e.what());
    }
    if (stored) {
      dev.emulator->set_calibration(stored->calibration);
      dev.calibration_source = calibration_path(backend->identity().serial);
    }
  }
  dev.backend = std::move(backend);
  return dev;
}

OpenedDevice open_openhaptics(const DeviceSpec& spec, const OpenOptions& oo) {
  hw::OpenHapticsOptions ho;
  ho.config = spec.argument;
  try {
    ho.command = hw::parse_hd_command(oo.hd_command);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--hd-command: ") + e.what());
  }
  OpenedDevice dev;
  dev.backend = std::make_unique<hw::OpenHapticsBackend>(ho);
  dev.calibration_source = "the OpenHaptics driver (hdCheckCalibration)";
  return dev;
}

// device nodes whose names start with `prefix` in /dev
Json dev_nodes(const std::string& prefix) {
  Json out = Json::array();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/dev", ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(prefix, 0) == 0) out.push_back(e.path().string());
  }
  return out;
}

}  // namespace

DeviceSpec parse_device_spec(const std::string& text) {
  DeviceSpec s;
  const auto colon = text.find(':');
  s.backend = text.substr(0, colon);
  if (colon != std::string::npos) s.argument = text.substr(colon + 1);
  if (s.backend != "emulator" && s.backend != "openhaptics" &&
      s.backend != "firewire" && s.backend != "usb") {
    throw UsageError("--device: unknown backend '" + s.backend +
                     "' (expected emulator[:firewire][:case|scene.xml], "
                     "openhaptics[:CONFIG_NAME], firewire[:GUID] or "
                     "usb[:BUS-ADDR]; `vmhaptics hw list` shows what is "
                     "available)");
  }
  return s;
}

OpenedDevice open_device(const DeviceSpec& spec, const OpenOptions& options) {
  if (spec.backend == "emulator") return open_emulator(spec, options);
  return open_openhaptics(spec, options);
}

Json list_backends() {
  Json list = Json::array();
  list.push_back(Json{{"name", "emulator"},
                      {"device", "emulator[:case|scene.xml]"},
                      {"available", true},
                      {"found", "the MuJoCo Omni, scenes in " + studies::models_dir()},
                      {"verified_on_hardware", false}});
  Json oh{{"name", "openhaptics"},
          {"device", "openhaptics[:CONFIG_NAME]"},
          {"looked_for", hw::hd::HdLibrary::describe_search()},
          {"verified_on_hardware", false}};
  try {
    hw::hd::HdLibrary lib;
    oh["available"] = true;
    oh["found"] = lib.file();
  } catch (const DeviceOpenError& e) {
    oh["available"] = false;
    oh["why_not"] = e.what();
  }
  list.push_back(oh);
  list.push_back(Json{{"name", "firewire"},
                      {"device", "(native driver, not in this version)"},
                      {"available", false},
                      {"found", dev_nodes("fw")},
                      {"why_not", "the native FireWire Omni driver is not built "
                                  "yet; use openhaptics for a FireWire Omni"},
                      {"verified_on_hardware", false}});
  // the USB Touch through libusb (cli/hw_usb.cc): probe and capture only
  list.push_back(usb_touch_backend_json());
  return Json{{"backends", list}};
}

}  // namespace vmh::cli
