#include "cli/hw_backends.h"

#include <dirent.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "cli/args.h"
#include "cli/hw_calibration_store.h"
#include "cli/hw_usb.h"
#include "device/servo_thread.h"
#include "hw/firewire/firewire_omni.h"
#ifdef VMH_HAVE_RAW1394
#include "hw/firewire/raw1394_transport.h"
#endif
#include "hw/openhaptics/hd_library.h"
#include "hw/openhaptics/openhaptics_backend.h"
#include "sim/emulator.h"
#include "sim/emulator_firewire.h"
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

// The emulator's options from the spec and the common flags (UsageError
// naming the bad one). `what` names the device in messages.
sim::EmulatorOptions emulator_options(const DeviceSpec& spec, const OpenOptions& oo,
                                      const std::string& what) {
  sim::EmulatorOptions eo;
  std::string name;
  try {
    eo.scene = studies::resolve_scene(spec.argument.empty() ? "case1" : spec.argument,
                                      &name);
    // through the wire, --fault names packet faults (parsed by the caller)
    if (spec.wire.empty()) eo.faults = sim::parse_emulator_faults(oo.faults);
  } catch (const std::exception& e) {
    throw UsageError("--device " + what + ": " + e.what());
  }
  try {
    eo.seeded = sim::parse_seeded_faults(oo.seeded);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--emulator-fault: ") + e.what());
  }
  if (!spec.wire.empty()) {
    // the host's decoding is FirewireOmni's here, not the emulator's: a
    // mistake seeded into the emulator's decoding would never be seen
    for (const std::string& item : eo.seeded.items) {
      const bool decoding =
          item == "gimbal_swap" ||
          (item.rfind("joint", 0) == 0 && item.size() > 5 &&
           item.compare(item.size() - 5, 5, "_sign") == 0);
      if (decoding) {
        throw UsageError("--emulator-fault: " + item +
                         " is a mistake in the host's decoding, which --device " +
                         what + " does in the FireWire driver, not in the emulator");
      }
    }
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
  return eo;
}

// the stored calibration for a serial number, if any (UsageError when the
// file is malformed)
std::optional<StoredCalibration> stored_calibration(const OpenOptions& oo,
                                                    const std::string& serial) {
  if (!oo.load_calibration) return std::nullopt;
  try {
    return load_calibration(serial);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("stored calibration: ") + e.what());
  }
}

void describe_emulator(const sim::EmulatorOptions& eo, const OpenOptions& oo,
                       OpenedDevice* dev) {
  std::error_code ec;
  dev->scene = fs::absolute(eo.scene, ec).string();
  dev->hand = oo.hand;
  dev->model_file = eo.model_file;
  dev->seeded_faults = eo.seeded.items;
  dev->calibration_source = "factory (the emulator's own)";
}

// emulator:firewire[:SCENE]: the emulator behind the FireWire packets and
// the native driver's device layer, decoding with the calibration the
// emulator's raw values imply (its factory one) or the stored one
OpenedDevice open_emulator_firewire(const DeviceSpec& spec, const OpenOptions& oo) {
  const std::string what = "emulator:firewire";
  sim::EmulatorFirewireOptions fo;
  fo.emulator = emulator_options(spec, oo, what);
  try {
    fo.faults = sim::parse_wire_faults(oo.faults);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--fault: ") + e.what());
  }
  std::unique_ptr<sim::EmulatorFirewireTransport> transport;
  try {
    transport = std::make_unique<sim::EmulatorFirewireTransport>(fo);
  } catch (const sim::SimError& e) {
    throw UsageError("--device " + what + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError("--device " + what + ": " + e.what());
  }
  sim::Emulator* emu = transport->emulator();
  DeviceIdentity id = emu->identity();
  id.backend = what;
  id.model = "PHANTOM Omni (MuJoCo emulator, FireWire packets)";
  OpenedDevice dev;
  describe_emulator(fo.emulator, oo, &dev);
  hw::fw::FirewireOmniOptions wo;
  wo.calibration = emu->factory_calibration();
  wo.calibrated = true;
  const auto stored = stored_calibration(oo, id.serial);
  auto backend = std::make_unique<hw::fw::FirewireBackend>(std::move(transport), wo, id);
  if (stored) {
    backend->omni()->set_calibration(stored->calibration);
    // the emulator's own decoding too, so that its readings agree
    emu->set_calibration(stored->calibration);
    dev.calibration_source = calibration_path(id.serial);
  }
  dev.emulator = emu;
  dev.firewire = backend.get();
  dev.backend = std::move(backend);
  return dev;
}

OpenedDevice open_emulator(const DeviceSpec& spec, const OpenOptions& oo) {
  if (spec.wire == "firewire") return open_emulator_firewire(spec, oo);
  const sim::EmulatorOptions eo = emulator_options(spec, oo, "emulator");
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
  describe_emulator(eo, oo, &dev);
  if (const auto stored = stored_calibration(oo, backend->identity().serial)) {
    dev.emulator->set_calibration(stored->calibration);
    dev.calibration_source = calibration_path(backend->identity().serial);
  }
  dev.backend = std::move(backend);
  return dev;
}

// firewire[:GUID]: the Omni on the bus through libraw1394
OpenedDevice open_firewire(const DeviceSpec& spec, const OpenOptions& oo) {
  if (!oo.faults.empty()) {
    throw UsageError("--fault: only the emulator injects faults, not --device " +
                     spec.text());
  }
#ifdef VMH_HAVE_RAW1394
  hw::fw::Raw1394Options ro;
  if (!spec.argument.empty()) {
    try {
      ro.guid = hw::fw::parse_guid(spec.argument);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--device firewire: ") + e.what());
    }
  }
  auto transport = std::make_unique<hw::fw::Raw1394Transport>(ro);  // DeviceOpenError
  const hw::fw::NodeInfo node = transport->node();
  DeviceIdentity id;
  id.backend = "firewire";
  id.config = hw::fw::guid_text(node.guid);
  id.serial = node.serial.empty() ? hw::fw::guid_text(node.guid) : node.serial;
  id.driver_version = "vmhaptics native (libraw1394)";
  hw::fw::FirewireOmniOptions wo;  // nominal until calibrated
  OpenedDevice dev;
  dev.calibration_source =
      "nominal (docs/sources.md §9.2's example constants; run hw calibrate)";
  if (const auto stored = stored_calibration(oo, id.serial)) {
    wo.calibration = stored->calibration;
    wo.calibrated = true;
    dev.calibration_source = calibration_path(id.serial);
  }
  auto backend = std::make_unique<hw::fw::FirewireBackend>(std::move(transport), wo, id);
  dev.firewire = backend.get();
  dev.backend = std::move(backend);
  return dev;
#else
  (void)oo;
  throw DeviceOpenError("--device " + spec.text() +
                        ": this build has no libraw1394 (install libraw1394-dev "
                        "and configure the build again)");
#endif
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
[[maybe_unused]] Json dev_nodes(const std::string& prefix) {
  Json out = Json::array();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/dev", ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(prefix, 0) == 0) out.push_back(e.path().string());
  }
  return out;
}

// The native FireWire driver's row: available where the build has
// libraw1394; the Omnis it finds on the bus, or why none
Json firewire_row() {
  Json row{{"name", "firewire"},
           {"device", "firewire[:GUID]"},
           {"verified_on_hardware", false}};
#ifdef VMH_HAVE_RAW1394
  std::string why_not;
  const std::vector<hw::fw::NodeInfo> nodes = hw::fw::list_omni_nodes(&why_not);
  Json found = Json::array();
  for (const hw::fw::NodeInfo& n : nodes) {
    found.push_back(Json{{"guid", hw::fw::guid_text(n.guid)},
                         {"serial", n.serial},
                         {"port", n.port},
                         {"node", n.node},
                         {"description", n.description}});
  }
  row["available"] = true;
  row["found"] = found;
  if (nodes.empty()) {
    row["why_not"] = why_not.empty() ? std::string("no PHANTOM Omni found") : why_not;
  }
#else
  row["available"] = false;
  row["found"] = dev_nodes("fw");
  row["why_not"] = "this build has no libraw1394 (install libraw1394-dev and "
                   "configure the build again; hw/udev/60-vmhaptics.rules "
                   "gives access to /dev/fw*)";
#endif
  return row;
}

}  // namespace

std::string DeviceSpec::text() const {
  std::string t = backend;
  if (!wire.empty()) t += ":" + wire;
  if (!argument.empty()) t += ":" + argument;
  return t;
}

DeviceSpec parse_device_spec(const std::string& text) {
  DeviceSpec s;
  const auto colon = text.find(':');
  s.backend = text.substr(0, colon);
  if (colon != std::string::npos) s.argument = text.substr(colon + 1);
  if (s.backend == "emulator" &&
      (s.argument == "firewire" || s.argument.rfind("firewire:", 0) == 0)) {
    s.wire = "firewire";
    s.argument = s.argument.size() > 8 ? s.argument.substr(9) : "";
  }
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
  if (spec.backend == "firewire") return open_firewire(spec, options);
  if (spec.backend == "usb") {
    throw UsageError("usb: the Touch's payload protocol is not public; only hw "
                     "list, hw probe and hw capture take --device usb");
  }
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
  list.push_back(firewire_row());
  // the USB Touch through libusb (cli/hw_usb.cc): probe and capture only
  list.push_back(usb_touch_backend_json());
  list.push_back(Json{{"name", "emulator:firewire"},
                      {"device", "emulator:firewire[:case|scene.xml]"},
                      {"available", true},
                      {"found", "the MuJoCo Omni behind the FireWire Omni's "
                                "packets and the native driver, in process"},
                      {"verified_on_hardware", false}});
  return Json{{"backends", list}};
}

}  // namespace vmh::cli
