// A thin RAII layer over libusb-1.0: the context, the device list, an open
// handle, a claimed interface (released, and its kernel driver re-attached
// when this layer detached it), one transfer at a time with a timeout, and
// the sysfs facts libusb does not give (the kernel's cached descriptors and
// strings, the driver bound to an interface).
//
// libusb-1.0 API: https://libusb.sourceforge.io/api-1.0/ (Debian
// libusb-1.0-0-dev 1.0.26). The sysfs layout (/sys/bus/usb/devices/<port>,
// <port>:<config>.<interface>/driver): the kernel's
// Documentation/ABI/stable/sysfs-bus-usb.
#ifndef VMHAPTICS_HW_USB_USB_TRANSPORT_H_
#define VMHAPTICS_HW_USB_USB_TRANSPORT_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

struct libusb_context;
struct libusb_device;
struct libusb_device_handle;

namespace vmh::hw::usb {

// "LIBUSB_ERROR_ACCESS (Access denied (insufficient permissions))"
std::string usb_error_text(int libusb_error);

class UsbContext {
 public:
  // Throws UsbDeviceError when libusb cannot start (e.g. no usbfs).
  UsbContext();
  ~UsbContext();
  UsbContext(const UsbContext&) = delete;
  UsbContext& operator=(const UsbContext&) = delete;
  libusb_context* get() const { return ctx_; }

 private:
  libusb_context* ctx_ = nullptr;
};

// What one enumerated device is, without opening it.
struct UsbDeviceInfo {
  libusb_device* device = nullptr;  // owned by the UsbDeviceList
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  int bus = 0;
  int address = 0;
  std::string port_path;  // "1-2"
};

class UsbDeviceList {
 public:
  explicit UsbDeviceList(const UsbContext& ctx);
  ~UsbDeviceList();
  UsbDeviceList(const UsbDeviceList&) = delete;
  UsbDeviceList& operator=(const UsbDeviceList&) = delete;
  const std::vector<UsbDeviceInfo>& devices() const { return infos_; }

 private:
  libusb_device** list_ = nullptr;
  std::vector<UsbDeviceInfo> infos_;
};

class UsbHandle {
 public:
  // libusb_open; `error` gets the libusb error (0 when open)
  UsbHandle(libusb_device* device, int* error);
  ~UsbHandle();
  UsbHandle(const UsbHandle&) = delete;
  UsbHandle& operator=(const UsbHandle&) = delete;
  libusb_device_handle* get() const { return h_; }
  bool is_open() const { return h_ != nullptr; }

 private:
  libusb_device_handle* h_ = nullptr;
};

// Claims an interface for the life of the object. With `detach`, a kernel
// driver that libusb reports active is detached first, and re-attached on
// release. Throws UsbDeviceError naming the interface and the cause.
class ClaimedInterface {
 public:
  ClaimedInterface(UsbHandle* handle, int interface_number, bool detach,
                   const std::string& who);
  ~ClaimedInterface();
  ClaimedInterface(const ClaimedInterface&) = delete;
  ClaimedInterface& operator=(const ClaimedInterface&) = delete;
  bool detached() const { return detached_; }

 private:
  UsbHandle* handle_;
  int number_;
  bool detached_ = false;
};

// The outcome of one IN transfer.
enum class TransferOutcome { kCompleted, kTimedOut, kNoDevice, kStall, kOverflow, kError };
struct TransferResult {
  TransferOutcome outcome = TransferOutcome::kError;
  std::vector<std::uint8_t> data;  // what arrived (also on a timeout)
  std::string detail;              // libusb's name for an error
};
// One bulk or interrupt IN transfer of up to `length` bytes, waited for at
// most `timeout_ms`; a single transfer in flight (hw/usb/README.md says why).
TransferResult read_in_endpoint(const UsbContext& ctx, UsbHandle* handle,
                                std::uint8_t endpoint, bool interrupt,
                                int length, unsigned timeout_ms);

// 1: a kernel driver holds the interface, 0: none, nullopt: libusb could not
// tell (not supported here, or the handle is not open)
std::optional<bool> kernel_driver_active(UsbHandle* handle, int interface_number);

// A string descriptor through a control transfer, in ASCII; nullopt and
// `why` when it cannot be read.
std::optional<std::string> read_string_descriptor(UsbHandle* handle, std::uint8_t index,
                                                  std::string* why);

// ---- sysfs ----

// /sys/bus/usb/devices/<port_path>
std::string sysfs_device_dir(const std::string& port_path);
// the kernel's copy of the device's descriptors (sysfs `descriptors`);
// empty when it cannot be read
std::vector<std::uint8_t> sysfs_descriptors(const std::string& port_path);
// one attribute's first line ("" when absent); found = whether it exists
std::string sysfs_attribute(const std::string& port_path, const std::string& name,
                            bool* found);
// the name of the driver bound to <port>:<config>.<interface> ("cdc_acm"),
// "" when none is bound
std::string sysfs_interface_driver(const std::string& port_path, int config_value,
                                   int interface_number);

}  // namespace vmh::hw::usb

#endif  // VMHAPTICS_HW_USB_USB_TRANSPORT_H_
