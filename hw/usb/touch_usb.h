// The USB Touch (Geomagic / 3D Systems) through libusb: find it, describe it,
// and capture what its IN endpoints send. Nothing here decodes or sends a
// payload: the Touch's protocol is not public (docs/sources.md §9.3), and a
// guessed command to a force-feedback device could drive its motors.
// hw/usb/README.md describes the layers, the capture format and what has
// been verified (on a real Touch: nothing yet).
#ifndef VMHAPTICS_HW_USB_TOUCH_USB_H_
#define VMHAPTICS_HW_USB_TOUCH_USB_H_

#include <optional>
#include <string>
#include <vector>

#include "hw/usb/usb_descriptors.h"

namespace vmh::hw::usb {

// One Touch found on the bus.
struct TouchListing {
  std::string id;         // "2988:0302"
  int bus = 0;
  int address = 0;
  std::string port_path;  // "1-2"
  bool accessible = false;  // libusb_open succeeded
  std::string why_not;      // when not accessible
};

// Why a Touch at `where` could not be opened, from libusb_open's error:
// for LIBUSB_ERROR_ACCESS, the udev rule to install; else libusb's name.
std::string open_failure_text(int libusb_error, const BusAddress& where);

struct TouchScan {
  std::vector<TouchListing> found;
  // set when libusb itself could not start or list (then `found` is empty)
  std::string why_none;
};

// Every USB device whose IDs are in touch_ids(), by bus then address; each
// is opened once to say whether this user may use it. Never throws.
TouchScan list_touch_devices();

// A string descriptor as far as it could be read.
struct UsbStringReport {
  std::uint8_t index = 0;
  std::optional<std::string> value;
  std::string source;   // "sysfs" (the kernel's copy) or "device"
  std::string why_not;  // when value is empty
};

// Who holds one interface.
struct InterfaceDriver {
  int interface_number = 0;
  std::string sysfs_driver;  // "cdc_acm"; "" when none is bound
  // libusb_kernel_driver_active: nullopt when it could not be asked
  std::optional<bool> libusb_active;
};

struct TouchProbe {
  TouchListing device;
  UsbDescriptors descriptors;
  int active_configuration = 0;  // bConfigurationValue (sysfs)
  UsbStringReport manufacturer, product, serial;
  std::vector<InterfaceDriver> drivers;  // of the active configuration
};

// The Touch at `where`, or the first one (lowest bus, then address).
// Throws UsbUsageError when there is no device at `where`, it is not a
// Touch, or no Touch is present;
// UsbDeviceError when its descriptors cannot be read. A Touch that cannot
// be opened is still described (from sysfs); `device.why_not` says why.
TouchProbe probe_touch(const std::optional<BusAddress>& where);

struct CaptureOptions {
  std::optional<BusAddress> where;  // nullopt: the first Touch
  double duration_s = 0.0;          // > 0 and finite
  std::string out_path;
  bool detach = false;  // detach the kernel driver (cdc_acm) for the capture
  unsigned transfer_timeout_ms = 100;
};

struct CaptureResult {
  TouchListing device;
  int interface_number = 0;
  std::vector<std::uint8_t> endpoints;
  std::string kernel_driver;  // who held the interface before ("" none)
  bool detached = false;      // this capture detached it (and re-attached it)
  std::size_t transfers = 0;  // records written
  std::size_t bytes = 0;
  std::size_t timeouts = 0;   // transfers that ended with no data in time
  double elapsed_s = 0.0;
  std::string out_path;
  // empty when the capture ran its duration; else the cause, one line
  // (the file keeps every record and ends with "# error: ...")
  std::string error;
  bool device_lost = false;  // the cause was an unplug (LIBUSB_ERROR_NO_DEVICE)
};

// Reads every bulk and interrupt IN endpoint of the Touch's data interface
// for `duration_s`, one transfer at a time in turn, and writes each transfer
// to `out_path` as it arrives (hw/usb/README.md, "Capture format"). Throws
// UsbUsageError for bad options or no such Touch and UsbDeviceError when the
// device cannot be opened or claimed (a kernel driver holds the interface
// and `detach` is false): in both cases nothing is written. A failure during
// the capture is returned in `error`, with the file kept.
CaptureResult capture_touch(const CaptureOptions& options);

}  // namespace vmh::hw::usb

#endif  // VMHAPTICS_HW_USB_TOUCH_USB_H_
