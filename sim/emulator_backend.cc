#include "sim/emulator_backend.h"

#include <filesystem>
#include <memory>

#include "device/lockstep.h"
#include "device/servo_thread.h"
#include "hw/firewire/firewire_omni.h"
#include "hw/firewire/firewire_runtime.h"
#include "runtime/calibration_store.h"
#include "sim/cases/case_catalogue.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "sim/emulator_firewire.h"
#include "sim/fault_vocabulary.h"

namespace vmh::sim {
namespace {

namespace fs = std::filesystem;
using runtime::OpenedDevice;
using runtime::OpenRequest;
using runtime::RequestError;

// one period of the emulator's physics per lockstep tick
class EmulatorPlant final : public LockstepPlant {
 public:
  explicit EmulatorPlant(Emulator* emu) : emu_(emu) {}
  void advance_period() noexcept override { emu_->advance(); }

 private:
  Emulator* emu_;
};

// What the session and the verbs may ask of an emulator, whichever way it
// is reached.
class EmulatorCapabilities final : public runtime::TruthSource,
                                   public runtime::HandControl,
                                   public runtime::RawCalibration {
 public:
  explicit EmulatorCapabilities(Emulator* emu) : emu_(emu) {}
  void read_truth(PlantTruth* truth) const noexcept override {
    *truth = emu_->truth();
  }
  void set_hand_program(const std::string& name) override {
    try {
      emu_->set_hand_program(parse_hand_program(name));
    } catch (const std::invalid_argument& e) {
      throw RequestError(std::string("--hand: ") + e.what());
    }
  }
  hw::OmniCalibration calibration() const override {
    return emu_->calibration();
  }
  void set_calibration(const hw::OmniCalibration& c) override {
    emu_->set_calibration(c);
  }
  bool factory_calibration(hw::OmniCalibration* c) const override {
    *c = emu_->factory_calibration();
    return true;
  }

 private:
  Emulator* emu_;
};

// The emulator behind DeviceBackend: its physics thread and the project's
// own servo thread driving the loop, as a native driver does; or, in
// lockstep, both on the caller's thread.
class EmulatorBackend final : public DeviceBackend {
 public:
  explicit EmulatorBackend(const EmulatorOptions& o)
      : emu_(o), plant_(&emu_), lockstep_(emu_.servo_period_s()) {}
  ~EmulatorBackend() override { stop(); }

  DeviceIdentity identity() const override { return emu_.identity(); }
  CalibrationState calibration_state() override { return CalibrationState::kOk; }
  HapticDevice* device() noexcept override { return &emu_; }

  ServoReport start(ServoLoop* loop, const ServoOptions& options) override {
    if (options.lockstep != emu_.lockstep()) {
      throw DeviceOpenError(
          "emulator: opened for the " +
          std::string(emu_.lockstep() ? "lockstep" : "wall") +
          " clock, started on the other");
    }
    // a restarted loop (an HD program's hdStopScheduler, hdStartScheduler,
    // or the scheduler's restart when another device leaves) finds the
    // stylus where it was, as a real device's would be
    emu_.start(/*resume=*/true);
    if (options.lockstep) {
      lockstep_.start(loop, &plant_);
      ServoReport r;
      r.note = "lockstep: the loop runs on the caller's thread, one period "
               "of the emulator's physics per tick";
      return r;
    }
    thread_ = std::make_unique<ServoThread>(loop, options);
    return thread_->start();
  }
  void stop() noexcept override {
    if (thread_) thread_->stop();
    lockstep_.stop();
    (void)emu_.write_motor_torques(Vec3::Zero());
    emu_.stop();
  }
  bool running() const noexcept override {
    if (emu_.lockstep()) return lockstep_.running();
    return thread_ != nullptr && thread_->running();
  }
  TickStats timing() const override {
    if (emu_.lockstep()) return lockstep_.timing();
    return thread_ ? thread_->timing() : TickStats{};
  }
  void pass(double dt_s) override {
    if (emu_.lockstep()) {
      lockstep_.pass(dt_s);
      return;
    }
    DeviceBackend::pass(dt_s);
  }
  std::string stall_cause() const override { return emu_.stall_cause(); }

  Emulator* emulator() { return &emu_; }

 private:
  Emulator emu_;
  EmulatorPlant plant_;
  LockstepDriver lockstep_;
  std::unique_ptr<ServoThread> thread_;
};

// The emulator's options from the request (RequestError naming the bad
// one). `what` names the device in messages; `wire`: behind the packets.
EmulatorOptions emulator_options(const OpenRequest& rq, const std::string& what,
                                 bool wire) {
  EmulatorOptions eo;
  eo.lockstep = rq.lockstep;
  std::string name;
  try {
    eo.scene = resolve_scene(rq.argument.empty() ? "case1" : rq.argument, &name);
  } catch (const std::exception& e) {
    throw RequestError("--device " + what + ": " + e.what());
  }
  try {
    // through the wire, --fault names packet faults (parsed by the caller)
    if (!wire) eo.faults = parse_emulator_faults(rq.option("fault"));
  } catch (const std::invalid_argument& e) {
    throw RequestError(std::string("--fault: ") + e.what());
  }
  try {
    eo.seeded = parse_seeded_faults(rq.option("emulator-fault"));
  } catch (const std::invalid_argument& e) {
    throw RequestError(std::string("--emulator-fault: ") + e.what());
  }
  if (wire) {
    // the host's decoding is FirewireOmni's here, not the emulator's: a
    // mistake seeded into the emulator's decoding would never be seen
    for (const std::string& item : eo.seeded.items) {
      const bool decoding =
          item == "gimbal_swap" ||
          (item.rfind("joint", 0) == 0 && item.size() > 5 &&
           item.compare(item.size() - 5, 5, "_sign") == 0);
      if (decoding) {
        throw RequestError("--emulator-fault: " + item +
                           " is a mistake in the host's decoding, which "
                           "--device " + what +
                           " does in the FireWire driver, not in the emulator");
      }
    }
  }
  const std::string model = rq.option("model");
  if (!model.empty()) {
    std::error_code ec;
    if (!fs::is_regular_file(model, ec)) {
      throw RequestError("--model: no such file '" + model + "'");
    }
    eo.model_file = fs::absolute(model, ec).string();
  }
  eo.overrides = rq.scene_sets;
  try {
    eo.hand = parse_hand_program(rq.option("hand").empty() ? "tour"
                                                           : rq.option("hand"));
  } catch (const std::invalid_argument& e) {
    throw RequestError(std::string("--hand: ") + e.what());
  }
  return eo;
}

// the stored calibration for a serial number, if any
std::optional<runtime::StoredCalibration> stored_calibration(
    const OpenRequest& rq, const std::string& serial) {
  if (!rq.load_calibration) return std::nullopt;
  try {
    return runtime::load_calibration(serial);
  } catch (const runtime::CalibrationError& e) {
    throw RequestError(std::string("stored calibration: ") + e.what());
  }
}

// What every emulated device adds: its capabilities, the script's phase
// names when it plays the case, and meta.json's "emulator" entry.
void describe(const EmulatorOptions& eo, const std::string& hand,
              Emulator* emu, OpenedDevice* dev) {
  auto caps = std::make_shared<EmulatorCapabilities>(emu);
  dev->truth = caps.get();
  dev->hand = caps.get();
  dev->raw = caps.get();
  dev->keep = caps;
  dev->calibration_source = "factory (the emulator's own)";
  if (eo.hand == HandProgram::kCase) {
    for (const ScriptSegment& s : emu->loop().script().segments()) {
      dev->phases.push_back(s.name);
    }
  }
  std::error_code ec;
  const std::string scene = fs::absolute(eo.scene, ec).string();
  const std::string model = eo.model_file;
  const std::vector<std::string> seeded = eo.seeded.items;
  dev->meta = [scene, hand, model, seeded]() {
    // what compare needs to simulate the same scene; the seeded faults are
    // the emulator's hidden setup, there for tests to grade compare by
    return Json{{"emulator",
                 Json{{"scene", scene},
                      {"hand", hand},
                      {"model", model.empty() ? Json(nullptr) : Json(model)},
                      {"seeded_faults", seeded},
                      {"seeded_faults_note",
                       "the emulator's hidden setup, for tests only: an "
                       "analysis must not read it"}}}};
  };
}

OpenedDevice open_emulator(const OpenRequest& rq) {
  const EmulatorOptions eo = emulator_options(rq, "emulator", false);
  std::unique_ptr<EmulatorBackend> backend;
  try {
    backend = std::make_unique<EmulatorBackend>(eo);
  } catch (const SimError& e) {
    // a bad scene or --model file, named in the message
    throw RequestError(std::string("--device emulator: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw RequestError(std::string("--device emulator: ") + e.what());
  }
  OpenedDevice dev;
  Emulator* emu = backend->emulator();
  describe(eo, rq.option("hand").empty() ? "tour" : rq.option("hand"), emu, &dev);
  if (const auto stored = stored_calibration(rq, backend->identity().serial)) {
    emu->set_calibration(stored->calibration);
    dev.calibration_source = runtime::calibration_path(backend->identity().serial);
  }
  dev.backend = std::move(backend);
  return dev;
}

// emulator:firewire: the emulator behind the FireWire packets and the
// native driver's device layer, decoding with the calibration the
// emulator's raw values imply (its factory one) or the stored one
OpenedDevice open_emulator_firewire(const OpenRequest& rq) {
  const std::string what = "emulator:firewire";
  EmulatorFirewireOptions fo;
  fo.emulator = emulator_options(rq, what, true);
  try {
    fo.faults = parse_wire_faults(rq.option("fault"));
  } catch (const std::invalid_argument& e) {
    throw RequestError(std::string("--fault: ") + e.what());
  }
  std::unique_ptr<EmulatorFirewireTransport> transport;
  try {
    transport = std::make_unique<EmulatorFirewireTransport>(fo);
  } catch (const SimError& e) {
    throw RequestError("--device " + what + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw RequestError("--device " + what + ": " + e.what());
  }
  Emulator* emu = transport->emulator();
  DeviceIdentity id = emu->identity();
  id.backend = what;
  id.model = "PHANTOM Omni (MuJoCo emulator, FireWire packets)";
  OpenedDevice dev;
  describe(fo.emulator, rq.option("hand").empty() ? "tour" : rq.option("hand"),
           emu, &dev);
  hw::fw::FirewireOmniOptions wo;
  wo.calibration = emu->factory_calibration();
  wo.calibrated = true;
  const auto stored = stored_calibration(rq, id.serial);
  auto plant = std::make_shared<EmulatorPlant>(emu);
  auto backend = std::make_unique<hw::fw::FirewireBackend>(
      std::move(transport), wo, id, plant.get());
  hw::fw::FirewireBackend* fw = backend.get();
  if (stored) {
    fw->omni()->set_calibration(stored->calibration);
    // the emulator's own decoding too, so that its readings agree
    emu->set_calibration(stored->calibration);
    dev.calibration_source = runtime::calibration_path(id.serial);
  }
  // the driver decodes: calibration goes to it (and to the emulator, whose
  // own readings then agree); the capabilities stay the emulator's
  struct FirewireCalibration final : runtime::RawCalibration {
    hw::fw::FirewireBackend* fw;
    Emulator* emu;
    hw::OmniCalibration calibration() const override {
      return fw->omni()->calibration();
    }
    void set_calibration(const hw::OmniCalibration& c) override {
      fw->omni()->set_calibration(c);
      emu->set_calibration(c);
    }
    bool factory_calibration(hw::OmniCalibration* c) const override {
      *c = emu->factory_calibration();
      return true;
    }
  };
  auto cal = std::make_shared<FirewireCalibration>();
  cal->fw = fw;
  cal->emu = emu;
  dev.raw = cal.get();
  auto emulator_meta = dev.meta;
  dev.meta = [emulator_meta, fw]() {
    Json m = emulator_meta();
    m["firewire"] = hw::fw::firewire_meta_json(*fw);
    return m;
  };
  // the adapters live as long as the device
  dev.keep = std::make_shared<std::tuple<std::shared_ptr<void>,
                                         std::shared_ptr<EmulatorPlant>,
                                         std::shared_ptr<FirewireCalibration>>>(
      dev.keep, plant, cal);
  dev.backend = std::move(backend);
  return dev;
}

const std::vector<runtime::BackendOption>& emulator_option_list() {
  // the faults' help comes from the one fault table (sim/fault_vocabulary.h)
  static const std::vector<runtime::BackendOption> options = {
      {"hand",
       "what holds the emulated stylus: case, tour, none, dock, gimbal_sweep, "
       "manual (a program's hand, as view --serve-hd's mouse; from here it "
       "never grabs, so as none) (default depends on the verb)"},
      {"fault",
       "injected faults, comma-separated kind@t[:...] (t: emulator time, s). "
       "emulator: " + fault_help(kTransportFaults) +
           ". emulator:firewire (packets): " + fault_help(kWireFaults)},
      {"emulator-fault",
       "seeded faults for bring-up tests, comma-separated: " +
           fault_help(kSeededFaults) + " (docs/hardware.md)"},
      {"model",
       "a calibrated Omni MJCF (e.g. models/omni/calibrated/<serial>.xml) "
       "whose parameters replace the scene's Omni's"},
  };
  return options;
}

}  // namespace

void register_backends(runtime::BackendRegistry* registry) {
  const auto add = [registry](const char* name, const char* summary,
                              const char* found,
                              runtime::OpenedDevice (*open)(const OpenRequest&)) {
    runtime::BackendInfo b;
    b.name = name;
    b.grammar = std::string(name) + "[:case|scene.xml]";
    b.summary = summary;
    b.options = emulator_option_list();
    b.simulated = true;
    const std::string where = found;
    b.list = [where] {
      return Json{{"available", true},
                  {"found", where},
                  {"clocks", {"realtime", "lockstep"}},
                  {"verified_on_hardware", false}};
    };
    b.open = open;
    registry->add(std::move(b));
  };
  add("emulator", "the MuJoCo Omni held by a simulated hand",
      ("the MuJoCo Omni, scenes in " + models_dir()).c_str(), open_emulator);
  add("emulator:firewire", "the MuJoCo Omni behind the FireWire Omni's packets",
      "the MuJoCo Omni behind the FireWire Omni's packets and the native "
      "driver, in process",
      open_emulator_firewire);
}

}  // namespace vmh::sim
