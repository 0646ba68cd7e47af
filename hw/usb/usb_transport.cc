#include "hw/usb/usb_transport.h"

#include <libusb.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

#include "hw/usb/usb_descriptors.h"

namespace vmh::hw::usb {

std::string usb_error_text(int e) {
  return std::string(libusb_error_name(e)) + " (" + libusb_strerror(e) + ")";
}

UsbContext::UsbContext() {
  const int r = libusb_init(&ctx_);
  if (r != 0) {
    ctx_ = nullptr;
    throw UsbDeviceError("libusb could not start: " + usb_error_text(r) +
                         " (no USB device filesystem at /dev/bus/usb?)");
  }
}

UsbContext::~UsbContext() {
  if (ctx_ != nullptr) libusb_exit(ctx_);
}

UsbDeviceList::UsbDeviceList(const UsbContext& ctx) {
  const ssize_t n = libusb_get_device_list(ctx.get(), &list_);
  if (n < 0) {
    list_ = nullptr;
    throw UsbDeviceError("libusb could not list the USB devices: " +
                         usb_error_text(static_cast<int>(n)));
  }
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device* d = list_[i];
    libusb_device_descriptor desc{};
    if (libusb_get_device_descriptor(d, &desc) != 0) continue;
    UsbDeviceInfo info;
    info.device = d;
    info.vendor_id = desc.idVendor;
    info.product_id = desc.idProduct;
    info.bus = libusb_get_bus_number(d);
    info.address = libusb_get_device_address(d);
    std::uint8_t ports[8];
    const int np = libusb_get_port_numbers(d, ports, 8);
    info.port_path = format_port_path(
        info.bus, np > 0 ? std::vector<std::uint8_t>(ports, ports + np)
                         : std::vector<std::uint8_t>{});
    infos_.push_back(info);
  }
}

UsbDeviceList::~UsbDeviceList() {
  if (list_ != nullptr) libusb_free_device_list(list_, 1);
}

UsbHandle::UsbHandle(libusb_device* device, int* error) {
  const int r = libusb_open(device, &h_);
  if (r != 0) h_ = nullptr;
  if (error != nullptr) *error = r;
}

UsbHandle::~UsbHandle() {
  if (h_ != nullptr) libusb_close(h_);
}

ClaimedInterface::ClaimedInterface(UsbHandle* handle, int interface_number,
                                   bool detach, const std::string& who)
    : handle_(handle), number_(interface_number) {
  const std::string where = "interface " + std::to_string(interface_number) + " of " + who;
  if (detach && libusb_kernel_driver_active(handle->get(), number_) == 1) {
    const int r = libusb_detach_kernel_driver(handle->get(), number_);
    if (r != 0 && r != LIBUSB_ERROR_NOT_FOUND) {
      throw UsbDeviceError("could not detach the kernel driver from " + where + ": " +
                           usb_error_text(r));
    }
    detached_ = (r == 0);
  }
  const int r = libusb_claim_interface(handle->get(), number_);
  if (r != 0) {
    if (detached_) (void)libusb_attach_kernel_driver(handle->get(), number_);
    std::string hint;
    if (r == LIBUSB_ERROR_BUSY) hint = "; another driver or program holds it";
    throw UsbDeviceError("could not claim " + where + ": " + usb_error_text(r) + hint);
  }
}

ClaimedInterface::~ClaimedInterface() {
  (void)libusb_release_interface(handle_->get(), number_);
  if (detached_) (void)libusb_attach_kernel_driver(handle_->get(), number_);
}

namespace {
void LIBUSB_CALL on_transfer_done(libusb_transfer* t) {
  *static_cast<int*>(t->user_data) = 1;
}
}  // namespace

TransferResult read_in_endpoint(const UsbContext& ctx, UsbHandle* handle,
                                std::uint8_t endpoint, bool interrupt, int length,
                                unsigned timeout_ms) {
  TransferResult out;
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(length), 0);
  libusb_transfer* t = libusb_alloc_transfer(0);
  if (t == nullptr) {
    out.detail = "libusb_alloc_transfer failed";
    return out;
  }
  int done = 0;
  if (interrupt) {
    libusb_fill_interrupt_transfer(t, handle->get(), endpoint, buffer.data(), length,
                                   on_transfer_done, &done, timeout_ms);
  } else {
    libusb_fill_bulk_transfer(t, handle->get(), endpoint, buffer.data(), length,
                              on_transfer_done, &done, timeout_ms);
  }
  int r = libusb_submit_transfer(t);
  if (r != 0) {
    libusb_free_transfer(t);
    out.outcome = r == LIBUSB_ERROR_NO_DEVICE ? TransferOutcome::kNoDevice
                                              : TransferOutcome::kError;
    out.detail = "submitting the transfer: " + usb_error_text(r);
    return out;
  }
  while (done == 0) {
    r = libusb_handle_events_completed(ctx.get(), &done);
    if (r != 0 && r != LIBUSB_ERROR_INTERRUPTED) {
      // the transfer is still in flight: cancel it and wait for it to end
      (void)libusb_cancel_transfer(t);
      while (done == 0) {
        if (libusb_handle_events_completed(ctx.get(), &done) != 0) break;
      }
      out.detail = "handling USB events: " + usb_error_text(r);
      break;
    }
  }
  if (done != 0) {
    switch (t->status) {
      case LIBUSB_TRANSFER_COMPLETED: out.outcome = TransferOutcome::kCompleted; break;
      case LIBUSB_TRANSFER_TIMED_OUT: out.outcome = TransferOutcome::kTimedOut; break;
      case LIBUSB_TRANSFER_NO_DEVICE: out.outcome = TransferOutcome::kNoDevice; break;
      case LIBUSB_TRANSFER_STALL: out.outcome = TransferOutcome::kStall; break;
      case LIBUSB_TRANSFER_OVERFLOW: out.outcome = TransferOutcome::kOverflow; break;
      default: out.outcome = TransferOutcome::kError; break;
    }
    if (out.detail.empty()) out.detail = libusb_error_name(t->status);
    const int n = t->actual_length;
    if (n > 0) out.data.assign(buffer.begin(), buffer.begin() + n);
  }
  libusb_free_transfer(t);
  return out;
}

std::optional<bool> kernel_driver_active(UsbHandle* handle, int interface_number) {
  if (handle == nullptr || !handle->is_open()) return std::nullopt;
  const int r = libusb_kernel_driver_active(handle->get(), interface_number);
  if (r == 0 || r == 1) return r == 1;
  return std::nullopt;
}

std::optional<std::string> read_string_descriptor(UsbHandle* handle, std::uint8_t index,
                                                  std::string* why) {
  if (handle == nullptr || !handle->is_open()) {
    if (why) *why = "the device is not open";
    return std::nullopt;
  }
  unsigned char buf[256];
  const int r = libusb_get_string_descriptor_ascii(handle->get(), index, buf, sizeof buf);
  if (r < 0) {
    if (why) *why = "reading string descriptor " + std::to_string(index) + ": " + usb_error_text(r);
    return std::nullopt;
  }
  return std::string(reinterpret_cast<const char*>(buf), static_cast<std::size_t>(r));
}

std::string sysfs_device_dir(const std::string& port_path) {
  return "/sys/bus/usb/devices/" + port_path;
}

std::vector<std::uint8_t> sysfs_descriptors(const std::string& port_path) {
  std::ifstream in(sysfs_device_dir(port_path) + "/descriptors", std::ios::binary);
  if (!in) return {};
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in),
                                   std::istreambuf_iterator<char>());
}

std::string sysfs_attribute(const std::string& port_path, const std::string& name,
                            bool* found) {
  std::ifstream in(sysfs_device_dir(port_path) + "/" + name);
  if (found) *found = static_cast<bool>(in);
  std::string s;
  if (in) std::getline(in, s);
  return s;
}

std::string sysfs_interface_driver(const std::string& port_path, int config_value,
                                   int interface_number) {
  const std::string link = sysfs_device_dir(port_path) + ":" +
                           std::to_string(config_value) + "." +
                           std::to_string(interface_number) + "/driver";
  char target[4096];
  const ssize_t n = readlink(link.c_str(), target, sizeof target - 1);
  if (n <= 0) return "";
  target[n] = '\0';
  const char* base = std::strrchr(target, '/');
  return base != nullptr ? std::string(base + 1) : std::string(target);
}

}  // namespace vmh::hw::usb
