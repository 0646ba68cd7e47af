// The FireWire Omni as a device backend of the runtime
// (runtime/backend_registry.h):
//   firewire[:GUID]   the Omni on the bus through libraw1394 (where the
//                     build has it); GUID: which one (default: the first
//                     found)
// and what meta.json records of any FirewireBackend (the native one, and
// the emulator behind the packets, sim/emulator_backend.cc).
#ifndef VMHAPTICS_HW_FIREWIRE_FIREWIRE_RUNTIME_H_
#define VMHAPTICS_HW_FIREWIRE_FIREWIRE_RUNTIME_H_

#include "hw/firewire/firewire_omni.h"
#include "runtime/backend_registry.h"

namespace vmh::hw::fw {

void register_firewire_backend(runtime::BackendRegistry* registry);

// meta.json's "firewire": the node (GUID, vendor, serial, description, bus
// generation), the transport's and the device's packet counts
Json firewire_meta_json(FirewireBackend& backend);

// A FirewireBackend's decoding calibration as the runtime's capability
class FirewireRawCalibration final : public runtime::RawCalibration {
 public:
  explicit FirewireRawCalibration(FirewireBackend* fw) : fw_(fw) {}
  OmniCalibration calibration() const override {
    return fw_->omni()->calibration();
  }
  void set_calibration(const OmniCalibration& c) override {
    fw_->omni()->set_calibration(c);
  }

 private:
  FirewireBackend* fw_;
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_FIREWIRE_RUNTIME_H_
