// The USB Touch as a device backend of the runtime
// (runtime/backend_registry.h): `usb[:BUS-ADDR]`, listed and probed only
// (its descriptors, strings and kernel drivers): its payload protocol is
// not public, so it runs no servo loop. `hw capture` records its raw
// traffic (cli/hw_usb.cc).
#ifndef VMHAPTICS_HW_USB_USB_RUNTIME_H_
#define VMHAPTICS_HW_USB_USB_RUNTIME_H_

#include <optional>
#include <string>

#include "hw/usb/touch_usb.h"
#include "runtime/backend_registry.h"

namespace vmh::hw::usb {

void register_usb_backend(runtime::BackendRegistry* registry);

// what is said of every capture and probe: nothing decoded, and why
extern const char* const kNotDecoded;

// "" -> the first Touch; "1-5" -> that one. Throws runtime::RequestError.
std::optional<BusAddress> parse_where(const std::string& argument);

// The JSON of one Touch as listed, of a probe, of a capture
Json listing_json(const TouchListing& t);
Json probe_json(const TouchProbe& p);
Json capture_json(const CaptureResult& r);

}  // namespace vmh::hw::usb

#endif  // VMHAPTICS_HW_USB_USB_RUNTIME_H_
