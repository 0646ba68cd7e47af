#include "hw/firewire/firewire_runtime.h"

#include <memory>

#include "hw/firewire/raw1394_library.h"
#include "hw/firewire/raw1394_transport.h"
#include "runtime/calibration_store.h"

namespace vmh::hw::fw {

FirewireSpec parse_firewire_spec(const std::string& argument) {
  FirewireSpec spec;
  const std::size_t q = argument.find('?');
  const std::string guid = argument.substr(0, q);
  if (!guid.empty()) {
    try {
      spec.guid = parse_guid(guid);
    } catch (const std::invalid_argument& e) {
      throw runtime::RequestError(std::string("--device firewire: ") + e.what());
    }
  }
  if (q == std::string::npos) return spec;
  const std::string opts = argument.substr(q + 1);
  std::size_t from = 0;
  for (;;) {
    const std::size_t comma = opts.find(',', from);
    const std::string o = opts.substr(from, comma - from);
    if (o == "no-20010") {
      spec.write_20010 = false;
    } else if (o == "no-rehome") {
      spec.rehome_in_inkwell = false;
    } else {
      throw runtime::RequestError(
          "--device firewire: unknown option '" + o + "' after '?' (expected " +
          "no-20010, no-rehome, comma-separated: firewire[:GUID][?no-20010,"
          "no-rehome])");
    }
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  return spec;
}

namespace {

runtime::OpenedDevice open_firewire(const runtime::OpenRequest& rq) {
  const FirewireSpec spec = parse_firewire_spec(rq.argument);
  Raw1394Options ro;
  ro.guid = spec.guid;
  ro.write_20010 = spec.write_20010;
  auto transport = std::make_unique<Raw1394Transport>(ro);  // DeviceOpenError
  const NodeInfo node = transport->node();
  DeviceIdentity id;
  id.backend = "firewire";
  id.config = guid_text(node.guid);
  id.serial = node.serial.empty() ? guid_text(node.guid) : node.serial;
  id.driver_version = "vmhaptics native (libraw1394: " +
                      transport->library_file() + ")";
  FirewireOmniOptions wo;  // nominal until calibrated
  wo.rehome_in_inkwell = spec.rehome_in_inkwell;
  runtime::OpenedDevice dev;
  dev.calibration_source =
      "nominal (the public drivers' signs and gimbal lines, docs/sources.md "
      "§9.2; run hw calibrate)";
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

// the Omnis the bus has, or why none
Json list_firewire() {
  Json row{{"verified_on_hardware", false}};
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
  row["library"] = Raw1394Library::describe_search();
  row["available"] = !nodes.empty() || why_not.find("cannot load") == std::string::npos;
  row["found"] = found;
  if (nodes.empty()) {
    row["why_not"] = why_not.empty() ? std::string("no PHANTOM Omni found") : why_not;
  }
  return row;
}

}  // namespace

Json firewire_meta_json(FirewireBackend& backend) {
  const NodeInfo n = backend.transport()->node();
  const TransportStats t = backend.transport()->stats();
  const FirewireOmniStats d = backend.omni()->stats();
  Json m{{"node", Json{{"guid", n.guid},
                       {"vendor", n.vendor},
                       {"serial", n.serial},
                       {"serial_quadlet", n.serial_quadlet},
                       {"description", n.description},
                       {"generation", n.generation}}},
         {"transport", Json{{"received", t.received},
                            {"delivered", t.delivered},
                            {"superseded", t.superseded},
                            {"late", t.late},
                            {"sent", t.sent},
                            {"bad_packets", t.bad_packets},
                            {"timeouts", t.timeouts},
                            {"bus_resets", t.bus_resets},
                            {"recoveries", t.recoveries},
                            {"eagain_retries", t.eagain_retries},
                            {"stale_at_start", t.stale_at_start}}},
         {"device", Json{{"packets", d.packets},
                         {"lost_packets", d.lost_packets},
                         {"superseded_packets", d.superseded_packets},
                         {"late_packets", d.late_packets},
                         {"rehomes", d.rehomes},
                         {"bad_packets", d.bad_packets},
                         {"timeouts", d.timeouts},
                         {"bus_resets", d.bus_resets},
                         {"recoveries_failed", d.recoveries_failed},
                         {"commands", d.commands},
                         {"saturated_commands", d.saturated_commands}}}};
  if (const auto* raw = dynamic_cast<const Raw1394Transport*>(backend.transport())) {
    const StartRecord r = raw->start_record();
    m["start"] = Json{{"library", raw->library_file()},
                      {"tx_channel", r.tx_channel},
                      {"rx_channel", r.rx_channel},
                      {"wrote_20010", r.wrote_20010},
                      {"status_0x1083", r.status1},
                      {"status_0x1082", r.status2},
                      {"control_0x1087_before", r.control_before},
                      {"control_0x1087_written", r.control_written},
                      {"starts", r.starts}};
  }
  return m;
}

void register_firewire_backend(runtime::BackendRegistry* registry) {
  runtime::BackendInfo b;
  b.name = "firewire";
  b.grammar = "firewire[:GUID][?no-20010,no-rehome]";
  b.summary = "the FireWire PHANTOM Omni through libraw1394 (native driver)";
  b.list = list_firewire;
  b.open = open_firewire;
  registry->add(std::move(b));
}

}  // namespace vmh::hw::fw
