#include "hw/openhaptics/openhaptics_runtime.h"

#include <memory>

#include "hw/openhaptics/hd_library.h"
#include "hw/openhaptics/openhaptics_backend.h"

namespace vmh::hw {
namespace {

// the plant's truth behind the project's own HD library
class HdTruth final : public runtime::TruthSource {
 public:
  explicit HdTruth(const OpenHapticsBackend* b) : b_(b) {}
  void read_truth(PlantTruth* truth) const noexcept override {
    if (!b_->read_truth(truth)) *truth = PlantTruth{};
  }

 private:
  const OpenHapticsBackend* b_;
};

runtime::OpenedDevice open_openhaptics(const runtime::OpenRequest& rq) {
  OpenHapticsOptions ho;
  ho.config = rq.argument;
  const std::string command = rq.option("hd-command");
  try {
    ho.command = parse_hd_command(command.empty() ? "joint_torque" : command);
  } catch (const std::invalid_argument& e) {
    throw runtime::RequestError(std::string("--hd-command: ") + e.what());
  }
  runtime::OpenedDevice dev;
  auto backend = std::make_unique<OpenHapticsBackend>(ho);
  if (backend->has_truth()) {
    // the project's own library over a simulated device: the claims can be
    // judged on its truth, as on the emulator
    PlantTruth probe;
    if (backend->read_truth(&probe)) {
      auto truth = std::make_shared<HdTruth>(backend.get());
      dev.truth = truth.get();
      dev.keep = truth;
    }
  }
  dev.backend = std::move(backend);
  dev.calibration_source = "the OpenHaptics driver (hdCheckCalibration)";
  return dev;
}

}  // namespace

void register_openhaptics_backend(runtime::BackendRegistry* registry) {
  runtime::BackendInfo b;
  b.name = "openhaptics";
  b.grammar = "openhaptics[:CONFIG_NAME]";
  b.summary = "the vendor's OpenHaptics driver (libHD.so, loaded at run time)";
  b.options = {{"hd-command",
                "openhaptics: joint_torque (HD_CURRENT_JOINT_TORQUE, mN m; "
                "default) or force (HD_CURRENT_FORCE, N)"}};
  b.list = [] {
    Json row{{"looked_for", hd::HdLibrary::describe_search()},
             {"verified_on_hardware", false}};
    try {
      hd::HdLibrary lib;
      row["available"] = true;
      row["found"] = lib.file();
    } catch (const DeviceOpenError& e) {
      row["available"] = false;
      row["why_not"] = e.what();
    }
    return row;
  };
  b.open = open_openhaptics;
  registry->add(std::move(b));
}

}  // namespace vmh::hw
