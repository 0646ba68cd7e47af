#include "hw/firewire/firewire_runtime.h"

#include <memory>

#include "runtime/calibration_store.h"
#ifdef VMH_HAVE_RAW1394
#include "hw/firewire/raw1394_transport.h"
#endif

namespace vmh::hw::fw {
namespace {

#ifdef VMH_HAVE_RAW1394
runtime::OpenedDevice open_firewire(const runtime::OpenRequest& rq) {
  Raw1394Options ro;
  if (!rq.argument.empty()) {
    try {
      ro.guid = parse_guid(rq.argument);
    } catch (const std::invalid_argument& e) {
      throw runtime::RequestError(std::string("--device firewire: ") + e.what());
    }
  }
  auto transport = std::make_unique<Raw1394Transport>(ro);  // DeviceOpenError
  const NodeInfo node = transport->node();
  DeviceIdentity id;
  id.backend = "firewire";
  id.config = guid_text(node.guid);
  id.serial = node.serial.empty() ? guid_text(node.guid) : node.serial;
  id.driver_version = "vmhaptics native (libraw1394)";
  FirewireOmniOptions wo;  // nominal until calibrated
  runtime::OpenedDevice dev;
  dev.calibration_source =
      "nominal (docs/sources.md §9.2's example constants; run hw calibrate)";
  if (rq.load_calibration) {
    std::optional<runtime::StoredCalibration> stored;
    try {
      stored = runtime::load_calibration(id.serial);
    } catch (const runtime::CalibrationError& e) {
      throw runtime::RequestError(std::string("stored calibration: ") + e.what());
    }
    if (stored) {
      wo.calibration = stored->calibration;
      wo.calibrated = true;
      dev.calibration_source = runtime::calibration_path(id.serial);
    }
  }
  auto backend = std::make_unique<FirewireBackend>(std::move(transport), wo, id);
  FirewireBackend* fw = backend.get();
  auto cal = std::make_shared<FirewireRawCalibration>(fw);
  dev.raw = cal.get();
  dev.keep = cal;
  dev.meta = [fw]() { return Json{{"firewire", firewire_meta_json(*fw)}}; };
  dev.backend = std::move(backend);
  return dev;
}
#else
runtime::OpenedDevice open_firewire(const runtime::OpenRequest&) {
  throw DeviceOpenError("--device firewire: this build has no libraw1394 "
                        "(install libraw1394-dev and configure the build "
                        "again)");
}
#endif

// the Omnis the bus has, or why none
Json list_firewire() {
  Json row{{"verified_on_hardware", false}};
#ifdef VMH_HAVE_RAW1394
  std::string why_not;
  const std::vector<NodeInfo> nodes = list_omni_nodes(&why_not);
  Json found = Json::array();
  for (const NodeInfo& n : nodes) {
    found.push_back(Json{{"guid", guid_text(n.guid)},
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
  row["why_not"] =
      "this build has no libraw1394 (install libraw1394-dev and configure "
      "the build again)";
#endif
  return row;
}

}  // namespace

Json firewire_meta_json(FirewireBackend& backend) {
  const NodeInfo n = backend.transport()->node();
  const TransportStats t = backend.transport()->stats();
  const FirewireOmniStats d = backend.omni()->stats();
  return Json{{"node", Json{{"guid", n.guid},
                            {"vendor", n.vendor},
                            {"serial", n.serial},
                            {"description", n.description},
                            {"generation", n.generation}}},
              {"transport", Json{{"received", t.received},
                                 {"sent", t.sent},
                                 {"bad_packets", t.bad_packets},
                                 {"timeouts", t.timeouts},
                                 {"bus_resets", t.bus_resets},
                                 {"recoveries", t.recoveries}}},
              {"device", Json{{"packets", d.packets},
                              {"lost_packets", d.lost_packets},
                              {"bad_packets", d.bad_packets},
                              {"timeouts", d.timeouts},
                              {"bus_resets", d.bus_resets},
                              {"recoveries_failed", d.recoveries_failed},
                              {"commands", d.commands},
                              {"saturated_commands", d.saturated_commands}}}};
}

void register_firewire_backend(runtime::BackendRegistry* registry) {
  runtime::BackendInfo b;
  b.name = "firewire";
  b.grammar = "firewire[:GUID]";
  b.summary = "the FireWire PHANTOM Omni through libraw1394 (native driver)";
  b.list = list_firewire;
  b.open = open_firewire;
  registry->add(std::move(b));
}

}  // namespace vmh::hw::fw
