// What a session's meta.json and the hw verbs' JSON say about the device
// and the session: identity, calibration, software version and date, the
// loop's clock and timing, the stop reason, and the backend's own entries
// (OpenedDevice::meta: "emulator", "firewire"). docs/outputs.md lists the
// keys.
#ifndef VMHAPTICS_RUNTIME_META_H_
#define VMHAPTICS_RUNTIME_META_H_

#include <string>

#include "device/device_backend.h"
#include "runtime/backend_registry.h"
#include "runtime/json_util.h"
#include "runtime/session.h"

namespace vmh::runtime {

Json identity_json(const DeviceIdentity& id);
Json timing_json(const TickStats& t, const std::string& clock);
Json session_json(const SessionResult& r);
// {"state": ..., "source": ...}
Json calibration_json(OpenedDevice* dev);
// meta.json: {"verb": "hw <verb>", "software", "date_utc", "device",
// "calibration", "session", "period_histogram", backend entries..., extra's}
Json meta_json(OpenedDevice* dev, const SessionResult& r,
               const std::string& verb, const Json& extra);

// the software's name and version, as every output carries them
Json software_json();

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_META_H_
