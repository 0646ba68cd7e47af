// The device backends the runtime can open, each registered once, with
// everything about it in its own folder: its name, the grammar of its
// `--device` spec, the options it takes, how it lists what it finds (or
// why not) and how it opens. Nothing else in the program picks a backend
// by name.
//
// Who registers what (one line each):
//   hw/backends.cc        openhaptics, firewire, usb, served, replay (no MuJoCo)
//   sim/emulator_backend  emulator, emulator:firewire       (MuJoCo)
// The command line calls hw::register_backends() and, where the build has
// the testbed, sim::register_backends() before it parses.
//
// A spec is NAME[:ARGUMENT] or NAME?OPTIONS; NAME is the longest
// registered name that the spec is or begins with followed by ':' or '?'
// ("emulator:firewire:case2" is the backend "emulator:firewire" with the
// argument "case2"; "firewire?no-20010" is "firewire" with "?no-20010").
#ifndef VMHAPTICS_RUNTIME_BACKEND_REGISTRY_H_
#define VMHAPTICS_RUNTIME_BACKEND_REGISTRY_H_

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "device/device_backend.h"
#include "device/tick_record.h"
#include "hw/omni_calibration.h"
#include "runtime/json_util.h"

namespace vmh::runtime {

// A request that cannot be met as asked: an unknown backend, an option the
// backend does not take, a bad value. The message names what was wrong;
// the command line exits 2 on it, as on DeviceOpenError.
struct RequestError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// -- what an opened device can do beyond DeviceBackend (nullptr: not) --

// The simulated plant's truth (device/tick_record.h) for the tick the
// device last published: read by the session's loop after each tick.
// Thread-safe against the plant's own thread; no allocation.
class TruthSource {
 public:
  virtual ~TruthSource() = default;
  virtual void read_truth(PlantTruth* truth) const noexcept = 0;
};

// A simulated hand that can be told what to do (the emulator's hand
// programs: "case", "tour", "none", "dock", "gimbal_sweep"). Any thread.
class HandControl {
 public:
  virtual ~HandControl() = default;
  // throws RequestError naming an unknown program
  virtual void set_hand_program(const std::string& name) = 0;
};

// A device whose raw sensor values the host decodes (the FireWire Omni,
// the emulator): the calibration it decodes with, which `hw calibrate`
// fits and stores.
class RawCalibration {
 public:
  virtual ~RawCalibration() = default;
  virtual hw::OmniCalibration calibration() const = 0;
  // throws std::invalid_argument naming a bad field
  virtual void set_calibration(const hw::OmniCalibration& c) = 0;
  // the exact calibration, where the device is simulated and knows it
  virtual bool factory_calibration(hw::OmniCalibration* c) const {
    (void)c;
    return false;
  }
};

// An opened backend and what the session and the verbs may ask of it.
struct OpenedDevice {
  std::unique_ptr<DeviceBackend> backend;
  // where the joint-angle calibration in use came from, for meta.json
  std::string calibration_source;
  TruthSource* truth = nullptr;
  HandControl* hand = nullptr;
  RawCalibration* raw = nullptr;
  // the hand script's segment names when the truth's segment indexes them
  // (the emulator playing a case): trace.csv's phase column
  std::vector<std::string> phases;
  // the backend's own entries of meta.json ("emulator": the scene, hand,
  // model and seeded faults; "firewire": the node and packet counts),
  // asked once the session has ended
  std::function<Json()> meta;
  // whatever the capabilities above point into, kept alive with the device
  std::shared_ptr<void> keep;
};

// What the verb asks of the backend.
struct OpenRequest {
  std::string argument;  // after "NAME:" (may be empty)
  // backend options by key (BackendInfo::options); given by the user
  std::map<std::string, std::string> options;
  // the verb's defaults, used for keys the backend takes and the user did
  // not give (the emulator's hand program: "tour" for record, "case" for
  // run)
  std::map<std::string, std::string> defaults;
  // case parameter overrides (--set), for a simulated scene
  std::vector<std::string> scene_sets;
  // load the stored calibration for the device's serial number
  bool load_calibration = true;
  // the session will run in lockstep (ServoOptions::lockstep): a simulated
  // plant is built for it (no physics thread), a replay steps its clock
  // with the ticks; others ignore it and refuse a lockstep start
  bool lockstep = false;

  // the option `key` as given, else its default, else ""
  std::string option(const std::string& key) const;
};

// One option a backend takes, and its help text (the command line makes a
// --KEY flag of each key some backend takes).
struct BackendOption {
  std::string key;
  std::string help;
};

struct BackendInfo {
  std::string name;       // "emulator", "openhaptics", ...
  std::string grammar;    // "emulator[:case|scene.xml]", for help and errors
  std::string summary;    // one line
  std::vector<BackendOption> options;
  // runs a servo loop (false: list and probe only, e.g. the USB Touch)
  bool servo = true;
  // a simulated plant: takes a scene as its argument, can run in lockstep,
  // has a truth
  bool simulated = false;
  // runs in lockstep though not simulated (a recording played back on the
  // loop's clock, hw/replay/): OpenRequest::lockstep is honoured. A
  // simulated backend runs in lockstep whatever this says.
  bool lockstep = false;
  bool can_lockstep() const { return simulated || lockstep; }
  // `hw list`'s fields for this backend beyond name and device:
  // "available", "found" or "why_not", anything else it knows. Never
  // throws: a failure is a why_not.
  std::function<Json()> list;
  // opens it. Throws RequestError (bad argument or option) or
  // DeviceOpenError (the device cannot be opened: the cause in one line).
  std::function<OpenedDevice(const OpenRequest&)> open;
  // probes it without a servo loop (servo = false backends): the JSON
  // `hw probe` prints. Throws as open does.
  std::function<Json(const std::string& argument)> probe;
};

class BackendRegistry {
 public:
  // the program's registry
  static BackendRegistry& global();

  // throws std::logic_error for a second backend of the same name or one
  // without a name, an open or a list function
  void add(BackendInfo info);

  const std::vector<BackendInfo>& all() const { return backends_; }
  const BackendInfo* find(const std::string& name) const;

  // The backend a spec names, and its argument. Throws RequestError naming
  // the spec and listing the grammars.
  const BackendInfo& resolve(const std::string& spec,
                             std::string* argument) const;

  // Opens the spec. Refuses (RequestError) an option the backend does not
  // take, naming the backends that do; a backend without a servo loop
  // when `servo` is asked for.
  OpenedDevice open(const std::string& spec, OpenRequest request,
                    bool servo = true) const;

  // `hw list`: {"backends": [{"name", "device", ...list()}, ...]}
  Json list() const;

  // every option key some backend takes, with its help and the backends
  // that take it ("emulator, emulator:firewire"), in first-seen order
  struct OptionUse {
    std::string key;
    std::string help;
    std::string backends;
  };
  std::vector<OptionUse> option_uses() const;

  // the grammars, comma-separated, for messages and help
  std::string grammars() const;

 private:
  std::vector<BackendInfo> backends_;
};

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_BACKEND_REGISTRY_H_
