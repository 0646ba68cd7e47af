#include "hw/served/served_runtime.h"

#include <memory>

#include "hw/served/served_device.h"

namespace vmh::hw::served {
namespace {

runtime::OpenedDevice open_served(const runtime::OpenRequest& rq) {
  if (rq.argument.empty()) {
    throw runtime::RequestError(
        "--device served: give the served name, served:NAME (`hw list` shows "
        "the devices served on this machine)");
  }
  const std::string bad = served_name_error(rq.argument);
  if (!bad.empty()) throw runtime::RequestError("--device served:NAME: " + bad);
  auto backend = std::make_unique<ServedBackend>(rq.argument);  // DeviceOpenError
  ServedBackend* b = backend.get();
  runtime::OpenedDevice dev;
  dev.calibration_source = "the server's (the served device decodes its own readings)";
  dev.meta = [b]() {
    const ServedState s = b->served()->last();
    return Json{{"served", Json{{"name", b->name()},
                                {"server_ticks", s.tick},
                                {"commands_written", b->served()->writes()},
                                {"commands_seen_by_server", s.commands_seen},
                                {"command_state",
                                 command_state_name(
                                     static_cast<CommandState>(s.command_state))}}}};
  };
  dev.backend = std::move(backend);
  return dev;
}

Json list_served_json() {
  Json row{{"verified_on_hardware", false}};
  Json found = Json::array();
  for (const ServedListing& l : list_served()) {
    Json f{{"name", l.name}, {"spec", "served:" + l.name},
           {"server_pid", l.server_pid}, {"serving", l.serving},
           {"client_pid", l.client_pid}};
    if (!l.model.empty()) f["model"] = l.model;
    if (!l.serial.empty()) f["serial"] = l.serial;
    if (!l.why_not.empty()) f["why_not"] = l.why_not;
    found.push_back(f);
  }
  row["available"] = true;
  row["found"] = found;
  if (found.empty()) {
    row["why_not"] = "no device is served on this machine (start one with "
                     "`vmhaptics view --serve-hd NAME`)";
  }
  return row;
}

}  // namespace

void register_served_backend(runtime::BackendRegistry* registry) {
  runtime::BackendInfo b;
  b.name = "served";
  b.grammar = "served:NAME";
  b.summary = "a device another process serves under NAME (vmhaptics view "
              "--serve-hd NAME), through shared memory";
  b.list = list_served_json;
  b.open = open_served;
  registry->add(std::move(b));
}

}  // namespace vmh::hw::served
