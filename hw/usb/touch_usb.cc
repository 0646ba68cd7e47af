#include "hw/usb/touch_usb.h"

#include <libusb.h>

#include <chrono>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <ctime>
#include <memory>

#include "hw/usb/usb_transport.h"

namespace vmh::hw::usb {
namespace {

using Clock = std::chrono::steady_clock;

std::string describe(const UsbDeviceInfo& d) {
  return format_usb_id(d.vendor_id, d.product_id) + " at bus " + std::to_string(d.bus) +
         " address " + std::to_string(d.address);
}

std::string open_failure(int error, const UsbDeviceInfo& d) {
  return open_failure_text(error, {d.bus, d.address});
}

TouchListing listing(const UsbDeviceInfo& d, int open_error) {
  TouchListing t;
  t.id = format_usb_id(d.vendor_id, d.product_id);
  t.bus = d.bus;
  t.address = d.address;
  t.port_path = d.port_path;
  t.accessible = open_error == 0;
  if (!t.accessible) t.why_not = open_failure(open_error, d);
  return t;
}

// the device at `where` (must be a Touch), or the first Touch
const UsbDeviceInfo& select_touch(const UsbDeviceList& list,
                                  const std::optional<BusAddress>& where) {
  if (where) {
    for (const UsbDeviceInfo& d : list.devices()) {
      if (d.bus != where->bus || d.address != where->address) continue;
      if (!is_touch_id(d.vendor_id, d.product_id)) {
        throw UsbUsageError("--device usb:" + std::to_string(where->bus) + "-" +
                            std::to_string(where->address) + ": the device there is " +
                            format_usb_id(d.vendor_id, d.product_id) +
                            ", not a Touch (`vmhaptics hw list`)");
      }
      return d;
    }
    throw UsbUsageError("--device usb:" + std::to_string(where->bus) + "-" +
                        std::to_string(where->address) + ": no USB device at bus " +
                        std::to_string(where->bus) + " address " +
                        std::to_string(where->address) + " (`vmhaptics hw list`)");
  }
  // the first by bus, then address, so that "usb" names the same device
  // whatever order libusb enumerates in
  const UsbDeviceInfo* first = nullptr;
  for (const UsbDeviceInfo& d : list.devices()) {
    if (!is_touch_id(d.vendor_id, d.product_id)) continue;
    if (first == nullptr || d.bus < first->bus ||
        (d.bus == first->bus && d.address < first->address)) {
      first = &d;
    }
  }
  if (first != nullptr) return *first;
  throw UsbUsageError("--device usb: no USB Touch found (looked for 2988:0301, "
                      "2988:0302, 2988:0304 and 0301:2988)");
}

UsbDescriptors read_descriptors(const UsbDeviceInfo& d) {
  const std::vector<std::uint8_t> raw = sysfs_descriptors(d.port_path);
  if (raw.empty()) {
    throw UsbDeviceError("could not read the descriptors of " + describe(d) + " from " +
                         sysfs_device_dir(d.port_path) + "/descriptors");
  }
  try {
    return parse_usb_descriptors(raw);
  } catch (const std::invalid_argument& e) {
    throw UsbDeviceError(describe(d) + ": " + e.what());
  }
}

int active_configuration(const UsbDeviceInfo& d, const UsbDescriptors& desc) {
  bool found = false;
  const std::string v = sysfs_attribute(d.port_path, "bConfigurationValue", &found);
  if (found && !v.empty()) return std::atoi(v.c_str());
  return desc.configurations.empty() ? 0 : desc.configurations.front().value;
}

const UsbConfiguration* find_configuration(const UsbDescriptors& desc, int value) {
  for (const UsbConfiguration& c : desc.configurations) {
    if (c.value == value) return &c;
  }
  return nullptr;
}

// sysfs first (the kernel read it at enumeration; no permission needed),
// then the device itself
UsbStringReport read_string(const UsbDeviceInfo& d, UsbHandle* handle,
                            const std::string& attribute, std::uint8_t index,
                            const std::string& open_why_not) {
  UsbStringReport s;
  s.index = index;
  if (index == 0) {
    s.why_not = "the device has no such string (index 0)";
    return s;
  }
  bool found = false;
  const std::string v = sysfs_attribute(d.port_path, attribute, &found);
  if (found) {
    s.value = v;
    s.source = "sysfs";
    return s;
  }
  if (handle == nullptr || !handle->is_open()) {
    s.why_not = "not in sysfs, and the device could not be opened: " + open_why_not;
    return s;
  }
  std::string why;
  s.value = read_string_descriptor(handle, index, &why);
  if (s.value) {
    s.source = "device";
  } else {
    s.why_not = "not in sysfs; " + why;
  }
  return s;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f != nullptr) std::fclose(f);
  }
};

}  // namespace

std::string open_failure_text(int libusb_error, const BusAddress& where) {
  const std::string node = usbfs_path(where);
  if (libusb_error == LIBUSB_ERROR_ACCESS) {
    return "permission denied opening " + node +
           ": install hw/udev/60-vmhaptics.rules (hw/udev/README.md, "
           "docs/hardware.md)";
  }
  return "could not open " + node + ": " + usb_error_text(libusb_error);
}

TouchScan list_touch_devices() {
  TouchScan scan;
  try {
    UsbContext ctx;
    UsbDeviceList list(ctx);
    for (const UsbDeviceInfo& d : list.devices()) {
      if (!is_touch_id(d.vendor_id, d.product_id)) continue;
      int error = 0;
      UsbHandle handle(d.device, &error);
      scan.found.push_back(listing(d, error));
    }
  } catch (const UsbDeviceError& e) {
    scan.found.clear();
    scan.why_none = e.what();
  }
  std::sort(scan.found.begin(), scan.found.end(),
            [](const TouchListing& a, const TouchListing& b) {
              return a.bus != b.bus ? a.bus < b.bus : a.address < b.address;
            });
  return scan;
}

TouchProbe probe_touch(const std::optional<BusAddress>& where) {
  UsbContext ctx;
  UsbDeviceList list(ctx);
  const UsbDeviceInfo& d = select_touch(list, where);
  TouchProbe p;
  int error = 0;
  UsbHandle handle(d.device, &error);
  p.device = listing(d, error);
  p.descriptors = read_descriptors(d);
  p.active_configuration = active_configuration(d, p.descriptors);
  const UsbDeviceDescriptor& dd = p.descriptors.device;
  p.manufacturer = read_string(d, &handle, "manufacturer", dd.manufacturer_index, p.device.why_not);
  p.product = read_string(d, &handle, "product", dd.product_index, p.device.why_not);
  p.serial = read_string(d, &handle, "serial", dd.serial_index, p.device.why_not);
  if (const UsbConfiguration* c = find_configuration(p.descriptors, p.active_configuration)) {
    for (const UsbInterface& i : c->interfaces) {
      if (i.alt_setting != 0) continue;
      InterfaceDriver drv;
      drv.interface_number = i.number;
      drv.sysfs_driver = sysfs_interface_driver(d.port_path, c->value, i.number);
      drv.libusb_active = kernel_driver_active(&handle, i.number);
      p.drivers.push_back(drv);
    }
  }
  return p;
}

namespace {

// A capture's options: a finite duration > 0 s and an output file.
void check_capture_options(const CaptureOptions& o) {
  if (!std::isfinite(o.duration_s) || !(o.duration_s > 0.0)) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", o.duration_s);
    throw UsbUsageError(std::string("--duration ") + buf +
                        ": must be a finite number of seconds > 0");
  }
  if (o.out_path.empty()) throw UsbUsageError("--out: a capture file is required");
}

// What a capture reads: the active configuration, its data interface (both
// in the descriptors they were found in) and that interface's IN endpoints.
struct CaptureTarget {
  const UsbConfiguration* config = nullptr;
  const UsbInterface* intf = nullptr;
  std::vector<UsbEndpoint> eps;
};

CaptureTarget capture_target(const UsbDeviceInfo& d, const UsbDescriptors& desc,
                             const std::string& who) {
  CaptureTarget t;
  t.config = find_configuration(desc, active_configuration(d, desc));
  if (t.config == nullptr) {
    throw UsbDeviceError(who + ": no active configuration in its descriptors");
  }
  t.intf = find_data_interface(*t.config);
  if (t.intf == nullptr) {
    throw UsbDeviceError(who + ": no interface with a bulk or interrupt IN endpoint");
  }
  t.eps = capture_endpoints(*t.intf);
  if (t.eps.empty()) {
    throw UsbDeviceError(who + ": interface " + std::to_string(t.intf->number) +
                         " has no bulk or interrupt IN endpoint to read");
  }
  return t;
}

// Who holds the data interface (r->kernel_driver, empty for no one); a
// UsbDeviceError unless the capture may detach it.
void check_kernel_driver(const UsbDeviceInfo& d, UsbHandle* handle,
                         const CaptureTarget& t, const std::string& who,
                         bool detach, CaptureResult* r) {
  // a kernel driver (cdc_acm) holds the data interface: release it only
  // when asked to, since that takes the device away from its serial port
  r->kernel_driver = sysfs_interface_driver(d.port_path, t.config->value, t.intf->number);
  const std::optional<bool> active = kernel_driver_active(handle, t.intf->number);
  if (r->kernel_driver.empty() && active.value_or(false)) r->kernel_driver = "a kernel driver";
  if (!r->kernel_driver.empty() && !detach) {
    throw UsbDeviceError("interface " + std::to_string(t.intf->number) + " of " + who +
                         " is held by " + r->kernel_driver +
                         "; pass --detach to release it for the capture (it is "
                         "re-attached afterwards)");
  }
}

// The capture file's header (hw/usb/README.md, "Capture format").
void write_capture_header(std::FILE* file, const UsbDeviceInfo& d,
                          const CaptureOptions& o, const CaptureResult& r) {
  CaptureHeader h;
  h.device_id = r.device.id;
  h.where = {d.bus, d.address};
  h.port_path = d.port_path;
  h.interface_number = r.interface_number;
  h.endpoints = r.endpoints;
  h.duration_s = o.duration_s;
  h.started_utc = utc_now();
  std::fputs(format_capture_header(h).c_str(), file);
  std::fflush(file);
}

// A transfer's outcome in r: a timeout with no data counted, a failure's
// cause in r->error (which ends the capture).
void note_outcome(const TransferResult& t, const UsbEndpoint& ep,
                  const std::string& who, CaptureResult* r) {
  char epname[8];
  std::snprintf(epname, sizeof epname, "0x%02x", static_cast<unsigned>(ep.address));
  switch (t.outcome) {
    case TransferOutcome::kCompleted: break;
    case TransferOutcome::kTimedOut:
      if (t.data.empty()) ++r->timeouts;
      break;
    case TransferOutcome::kNoDevice:
      r->device_lost = true;
      r->error = "the Touch " + who + " was unplugged during the capture "
                 "(LIBUSB_ERROR_NO_DEVICE on endpoint " + epname + ")";
      break;
    case TransferOutcome::kStall:
      r->error = "endpoint " + std::string(epname) + " of " + who + " stalled";
      break;
    case TransferOutcome::kOverflow:
      r->error = "endpoint " + std::string(epname) + " of " + who +
                 " sent more than wMaxPacketSize (" + std::to_string(ep.max_packet_size) +
                 " bytes)";
      break;
    case TransferOutcome::kError:
      r->error = "reading endpoint " + std::string(epname) + " of " + who + ": " + t.detail;
      break;
  }
}

// The capture itself: one IN transfer at a time, the endpoints in turn, each
// written to the file as it arrives, until o.duration_s is up or something
// fails (r->error); r->elapsed_s the time it took.
void capture_transfers(const UsbContext& ctx, UsbHandle* handle,
                       const std::vector<UsbEndpoint>& eps,
                       const CaptureOptions& o, const std::string& who,
                       std::FILE* file, CaptureResult* r) {
  const Clock::time_point t0 = Clock::now();
  const auto elapsed_s = [&]() {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  std::size_t next = 0;
  while (r->error.empty()) {
    const double left_s = o.duration_s - elapsed_s();
    if (left_s <= 0.0) break;
    const UsbEndpoint& ep = eps[next];
    next = (next + 1) % eps.size();
    const unsigned timeout_ms = static_cast<unsigned>(
        std::max(1.0, std::min<double>(o.transfer_timeout_ms, std::ceil(1e3 * left_s))));
    const TransferResult t = read_in_endpoint(ctx, handle, ep.address,
                                              ep.transfer_type == "interrupt",
                                              ep.max_packet_size, timeout_ms);
    const double t_s = elapsed_s();
    if (t.outcome == TransferOutcome::kCompleted ||
        (t.outcome == TransferOutcome::kTimedOut && !t.data.empty())) {
      const std::string line =
          format_capture_record(t_s, ep.address, t.data.data(), t.data.size());
      if (std::fputs(line.c_str(), file) < 0 || std::fflush(file) != 0) {
        r->error = "writing " + o.out_path + ": " + std::strerror(errno);
        break;
      }
      ++r->transfers;
      r->bytes += t.data.size();
    }
    note_outcome(t, ep, who, r);
  }
  r->elapsed_s = elapsed_s();
}

}  // namespace

CaptureResult capture_touch(const CaptureOptions& o) {
  check_capture_options(o);
  UsbContext ctx;
  UsbDeviceList list(ctx);
  const UsbDeviceInfo& d = select_touch(list, o.where);
  const std::string who = describe(d);
  const UsbDescriptors desc = read_descriptors(d);
  const CaptureTarget target = capture_target(d, desc, who);

  int error = 0;
  UsbHandle handle(d.device, &error);
  CaptureResult r;
  r.device = listing(d, error);
  if (!handle.is_open()) throw UsbDeviceError(who + ": " + r.device.why_not);
  r.interface_number = target.intf->number;
  for (const UsbEndpoint& e : target.eps) r.endpoints.push_back(e.address);
  check_kernel_driver(d, &handle, target, who, o.detach, &r);
  ClaimedInterface claim(&handle, target.intf->number, o.detach, who);
  r.detached = claim.detached();

  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(o.out_path.c_str(), "w"));
  if (!file) {
    throw UsbUsageError("--out " + o.out_path + ": cannot write: " + std::strerror(errno));
  }
  r.out_path = o.out_path;
  write_capture_header(file.get(), d, o, r);
  capture_transfers(ctx, &handle, target.eps, o, who, file.get(), &r);
  const std::string last = r.error.empty()
                               ? format_capture_end(r.transfers, r.bytes, r.timeouts, r.elapsed_s)
                               : format_capture_error(r.error, r.transfers);
  std::fputs(last.c_str(), file.get());
  std::fflush(file.get());
  return r;
}

}  // namespace vmh::hw::usb
