// Pure functions for the USB Touch (no libusb, no I/O): the table of the
// Touch's USB IDs and matching against it, the "2988:0302" and "1-2.3"
// spellings, the `usb:BUS-ADDR` argument, the parse of raw USB descriptors
// (device descriptor followed by configuration descriptors, as the Linux
// kernel exposes them in sysfs `descriptors`), and the lines of a capture
// file (hw/usb/README.md, "Capture format").
//
// Descriptor layouts: USB 2.0 specification, chapter 9 (§9.6.1 device,
// §9.6.3 configuration, §9.6.5 interface, §9.6.6 endpoint). The Touch's IDs:
// docs/sources.md §9.3.
#ifndef VMHAPTICS_HW_USB_USB_DESCRIPTORS_H_
#define VMHAPTICS_HW_USB_USB_DESCRIPTORS_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace vmh::hw::usb {

// Bad input from the user (an unknown BUS-ADDR, no Touch, a bad duration, an
// output file that cannot be written): nothing was done. One line.
class UsbUsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// The device could not be used (opened, claimed): nothing was written. One
// line naming the device and the cause.
class UsbDeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One USB ID pair a Touch has been seen with (docs/sources.md §9.3).
struct TouchId {
  std::uint16_t vendor_id;
  std::uint16_t product_id;
  const char* note;
};

// The four pairs: 0x2988:0x0301, 0x2988:0x0302, 0x2988:0x0304 and, on early
// units, 0x0301:0x2988 (vendor and product swapped).
const std::vector<TouchId>& touch_ids();
bool is_touch_id(std::uint16_t vendor_id, std::uint16_t product_id);

// "2988:0302": four lower-case hex digits each, as lsusb and udev spell them
std::string format_usb_id(std::uint16_t vendor_id, std::uint16_t product_id);

// "1-2.3": the bus, then the port numbers from the root hub down, as the
// kernel names the device in /sys/bus/usb/devices; "usb1" for a root hub
std::string format_port_path(int bus, const std::vector<std::uint8_t>& ports);

// bus number and device address, as in /dev/bus/usb/BBB/DDD
struct BusAddress {
  int bus = 0;
  int address = 0;
};
// "1-5" or "001-005" (bus 1, address 5). Throws UsbUsageError naming the
// text when it is not two decimal numbers in 1..255 joined by '-'.
BusAddress parse_bus_address(const std::string& text);
// "/dev/bus/usb/001/005"
std::string usbfs_path(const BusAddress& where);

// ---- descriptors ----

struct UsbEndpoint {
  std::uint8_t address = 0;           // bEndpointAddress, bit 7 = IN
  std::string direction;              // "in" or "out"
  std::string transfer_type;          // "control", "isochronous", "bulk", "interrupt"
  std::uint16_t max_packet_size = 0;  // wMaxPacketSize, bytes (bits 10..0)
  std::uint8_t interval = 0;          // bInterval, frames at full speed
};

struct UsbInterface {
  std::uint8_t number = 0;  // bInterfaceNumber
  std::uint8_t alt_setting = 0;
  std::uint8_t interface_class = 0;
  std::uint8_t interface_subclass = 0;
  std::uint8_t interface_protocol = 0;
  std::uint8_t string_index = 0;  // iInterface
  std::vector<UsbEndpoint> endpoints;
};

struct UsbConfiguration {
  std::uint8_t value = 0;  // bConfigurationValue
  std::uint8_t attributes = 0;
  int max_power_mA = 0;    // bMaxPower × 2 mA (full and high speed)
  std::vector<UsbInterface> interfaces;
};

struct UsbDeviceDescriptor {
  std::uint16_t bcd_usb = 0;
  std::uint8_t device_class = 0;
  std::uint8_t device_subclass = 0;
  std::uint8_t device_protocol = 0;
  std::uint8_t max_packet_size0 = 0;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::uint16_t bcd_device = 0;
  std::uint8_t manufacturer_index = 0;  // iManufacturer
  std::uint8_t product_index = 0;       // iProduct
  std::uint8_t serial_index = 0;        // iSerialNumber
  std::uint8_t num_configurations = 0;
};

struct UsbDescriptors {
  UsbDeviceDescriptor device;
  std::vector<UsbConfiguration> configurations;
};

// Parses a device descriptor followed by its configuration descriptors (each
// with its interface, endpoint and class-specific descriptors, the last
// skipped). Throws std::invalid_argument naming the byte offset and what is
// wrong when the bytes are not well-formed descriptors.
UsbDescriptors parse_usb_descriptors(const std::uint8_t* data, std::size_t size);
UsbDescriptors parse_usb_descriptors(const std::vector<std::uint8_t>& bytes);

// "2.00" for bcdUSB 0x0200, "1.00" for bcdDevice 0x0100
std::string format_bcd(std::uint16_t bcd);

// The interface a capture reads: the first with class 0x0A (CDC data, which
// is what cdc_acm binds the Touch's bulk endpoints through), else the first
// with a bulk or interrupt IN endpoint; nullptr when there is none.
const UsbInterface* find_data_interface(const UsbConfiguration& config);
// its bulk and interrupt IN endpoints, in descriptor order
std::vector<UsbEndpoint> capture_endpoints(const UsbInterface& interface);

// ---- the capture file (hw/usb/README.md, "Capture format") ----

struct CaptureHeader {
  std::string device_id;   // "2988:0302"
  BusAddress where;
  std::string port_path;   // "1-2"
  int interface_number = 0;
  std::vector<std::uint8_t> endpoints;
  double duration_s = 0.0;  // asked for
  std::string started_utc;  // ISO 8601
};
// two comment lines: what the file is, then the columns
std::string format_capture_header(const CaptureHeader& h);
// "0.001234 0x81 8 0102030405060708": seconds since the capture started
// (monotonic clock, 6 decimals), the endpoint, the length in bytes and the
// bytes as lower-case hex (nothing after the length when it is 0)
std::string format_capture_record(double t_s, std::uint8_t endpoint,
                                  const std::uint8_t* data, std::size_t size);
// the last line: "# end: N transfers, B bytes, T timeouts in D s" or
// "# error: WHY (N transfers kept)"
std::string format_capture_end(std::size_t transfers, std::size_t bytes,
                               std::size_t timeouts, double elapsed_s);
std::string format_capture_error(const std::string& why, std::size_t transfers);

// one data line read back: nullopt for a comment line; throws
// std::invalid_argument naming the line when it is neither
struct CaptureRecord {
  double t_s = 0.0;
  std::uint8_t endpoint = 0;
  std::vector<std::uint8_t> data;
};
std::optional<CaptureRecord> parse_capture_record(const std::string& line);

}  // namespace vmh::hw::usb

#endif  // VMHAPTICS_HW_USB_USB_DESCRIPTORS_H_
