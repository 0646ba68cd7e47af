// The FireWire Omni as a device backend of the runtime
// (runtime/backend_registry.h):
//   firewire[:GUID][?OPTION[,OPTION]]
//     the Omni on the bus through libraw1394 (loaded at run time:
//     raw1394_library.h); GUID: which one (default: the first found);
//     OPTION: no-20010 leaves the write to 0x20010 out of the start
//     sequence (two Omnis on one bus), no-rehome keeps the encoder offsets
//     when the stylus is docked
// and what meta.json records of any FirewireBackend (the native one, and
// the emulator behind the packets, sim/emulator_backend.cc).
#ifndef VMHAPTICS_HW_FIREWIRE_FIREWIRE_RUNTIME_H_
#define VMHAPTICS_HW_FIREWIRE_FIREWIRE_RUNTIME_H_

#include <cstdint>
#include <string>

#include "hw/firewire/firewire_omni.h"
#include "runtime/backend_registry.h"

namespace vmh::hw::fw {

void register_firewire_backend(runtime::BackendRegistry* registry);

// `--device firewire`'s argument (after "firewire:", or "?..." alone).
// Throws runtime::RequestError naming a bad GUID or an unknown option.
struct FirewireSpec {
  std::uint64_t guid = 0;
  bool write_20010 = true;
  bool rehome_in_inkwell = true;
};
FirewireSpec parse_firewire_spec(const std::string& argument);

// meta.json's "firewire": the node (GUID, vendor, serial, description, bus
// generation), the transport's and the device's packet counts, and on the
// bus what the start sequence did ("start")
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
