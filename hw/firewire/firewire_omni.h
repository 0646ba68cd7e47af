// The FireWire PHANTOM Omni as a HapticDevice and a DeviceBackend
// (`--device firewire[:GUID]`, and `--device emulator:firewire` over the
// emulator's in-process transport). Layers, as libnifalcon and libuvc have
// them:
//   transport (transport.h)   moves the packets: libraw1394, or in process
//   codec (omni_packet.h)     bytes <-> typed fields, pure functions
//   device (this file)        calibration (hw/omni_calibration.h), units,
//                             the device convention, lost-packet and
//                             bus-reset handling; the servo thread
//
// read_state(): one receive() (at most options.receive_timeout_s), which
// takes every packet that arrived since the last tick and hands over the
// newest; decoded to encoder counts (unwrapped from int16 to int32 across
// packets), pot codes (pot_code of the a/b words), buttons, the inkwell
// switch and a CLOCK_MONOTONIC timestamp; then angles_from_raw() with the
// calibration. Fills kStateJoints | kStateButtons | kStateInkwell |
// kStateTimestamp | kStateEncoders | kStatePots. Counts, from the device's
// packet counter and what the transport says arrived: lost packets (the
// counter moved further than the packets that arrived: the bus lost them),
// superseded ones (arrived, a newer one was used) and late ones (arrived a
// tick late). Maps TransportStatus to DeviceError: kTimeout -> kTimeout,
// kBusReset -> zero words with the motors off, recover(), kNotConnected
// for this tick (the encoder unwrap is re-seeded from the next packet),
// kDisconnected -> kNotConnected, kIo / kBadPacket -> kIo. A pot that
// reads open (a + b = 0) is kSensorFault.
//
// Re-homing (options.rehome_in_inkwell, on by default, as the public
// drivers do it): every packet that says the stylus is in the inkwell sets
// the encoder offsets so that t1..t3 read the calibration's
// inkwell_t123_rad. Encoders count from wherever they were when the
// device powered up (whether they reset then is not known), so a stored
// offset is right only until the device is restarted; the inkwell puts it
// right again.
//
// write_motor_torques(): per motor u = motor_sign * tau / full_scale_Nm,
// saturated to [-1, 1] by the codec; a non-finite torque sends zero words
// with the motors off and returns kInvalidCommand. The motors-on bit is set
// from the first finite write; stop sends zero words with it cleared.
//
// NOT VERIFIED ON A DEVICE (docs/hardware.md): the packet layout, the
// motor word's sign and full scale (kMotorFullScaleEstimate_Nm), the
// direction each encoder counts and each pot's line (nominal_calibration),
// the inkwell pose.
#ifndef VMHAPTICS_HW_FIREWIRE_FIREWIRE_OMNI_H_
#define VMHAPTICS_HW_FIREWIRE_FIREWIRE_OMNI_H_

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "device/device_backend.h"
#include "device/lockstep.h"
#include "device/haptic_device.h"
#include "device/seqlock.h"
#include "hw/firewire/omni_packet.h"
#include "hw/firewire/transport.h"
#include "hw/omni_calibration.h"

namespace vmh {
class ServoThread;
}

namespace vmh::hw::fw {

// Torque on a motor's joint at full-scale command u = +-1, N m: an
// ESTIMATE (no public source gives the DAC's scale). It is the rated torque
// limit (the 3.3 N peak force at the nominal pose, 3.3 x 0.13335 m,
// controller/omni_ratings.h), the largest limit the safety layer applies,
// so that no limit is cut by the codec. To be measured on a device
// (hw motor-test, then identify).
inline constexpr double kMotorFullScaleEstimate_Nm = 3.3 * 0.13335;

// A calibration to start from before `hw calibrate` has fitted the unit's
// own: the drivers' encoder signs (hw::kNominalEncoderSign) and gimbal
// lines (hw::kNominalPotGainPerRatio_rad, hw::kNominalPotOffset_rad, with
// r = code / kPotCodeMax), the estimated inkwell pose,
// encoder offsets zero until the stylus is first docked (re-homing), or
// angles relative to where the counters started without it. The pot
// constants differ per unit (§9.2): angles read through this are rough;
// calibration_state() says kNeedsUpdate.
inline OmniCalibration nominal_calibration() {
  OmniCalibration c;
  c.encoder_sign = kNominalEncoderSign;
  for (std::size_t i = 0; i < 3; ++i) {
    c.encoder_offset_rad[i] = 0.0;
    c.pot_gain_rad[i] = kNominalPotGainPerRatio_rad[i] / kPotCodeMax;
    c.pot_offset_rad[i] = kNominalPotOffset_rad[i];
  }
  return c;
}

struct FirewireOmniOptions {
  // how raw readings become angles
  OmniCalibration calibration = nominal_calibration();
  // true when `calibration` is this unit's own (a stored `hw calibrate`
  // fit); calibration_state() is then kOk, else kNeedsUpdate
  bool calibrated = false;
  // torque at u = +1 per motor t1..t3, N m (> 0, finite)
  std::array<double, 3> full_scale_Nm{kMotorFullScaleEstimate_Nm,
                                      kMotorFullScaleEstimate_Nm,
                                      kMotorFullScaleEstimate_Nm};
  // +1 or -1: the sign of u for a positive device-convention torque
  std::array<int, 3> motor_sign{+1, +1, +1};
  double receive_timeout_s = 2e-3;  // per read_state (> 0)
  // set the encoder offsets from every docked packet (see above)
  bool rehome_in_inkwell = true;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// What the device layer counted (safe to read from any thread).
struct FirewireOmniStats {
  std::uint64_t packets = 0;        // state packets decoded (one a tick)
  std::uint64_t lost_packets = 0;   // sent by the device, never arrived
  std::uint64_t superseded_packets = 0;  // arrived, a newer one was used
  std::uint64_t late_packets = 0;   // arrived a tick late (ReceiveInfo)
  std::uint64_t rehomes = 0;        // times the stylus went into the inkwell
                                    // and the encoder offsets were set
  std::uint64_t bad_packets = 0;    // refused by the codec or the transport
  std::uint64_t timeouts = 0;
  std::uint64_t bus_resets = 0;
  std::uint64_t recoveries_failed = 0;
  std::uint64_t commands = 0;       // command packets sent
  std::uint64_t saturated_commands = 0;  // a |u| > 1 was cut to 1
  std::uint32_t last_counter = 0;
};

class FirewireOmni final : public HapticDevice {
 public:
  // The transport is not owned and must outlive the device. Validates the
  // options (std::invalid_argument naming the field).
  FirewireOmni(Transport* transport, const FirewireOmniOptions& options);

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  DeviceError read_state(DeviceState* state) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // zero words, motors off (stop, faults)
  DeviceError send_zero() noexcept;

  // From one thread at a time, not the servo thread (validated; throws
  // std::invalid_argument); marks the device calibrated. The servo loop
  // takes it at its next tick.
  void set_calibration(const OmniCalibration& cal);
  bool calibrated() const noexcept {
    return calibrated_.load(std::memory_order_acquire);
  }
  // the calibration readings are decoded with: the one set last, with the
  // encoder offsets the inkwell has set since (any thread)
  OmniCalibration calibration() const noexcept;
  FirewireOmniStats stats() const noexcept { return stats_.read(); }
  // the last decoded packet (for `hw probe`)
  StatePacket last_packet() const noexcept { return last_.read(); }

 private:
  Transport* transport_;
  FirewireOmniOptions options_;
  // set_calibration()'s (its writer) and the servo loop's own copy with the
  // re-homed offsets (the servo thread is its only writer); the generation
  // says which set_calibration() a copy comes from
  Seqlock<OmniCalibration> cal_;
  std::atomic<std::uint64_t> cal_gen_{0};
  Seqlock<OmniCalibration> in_use_;
  std::atomic<std::uint64_t> in_use_gen_{0};
  Seqlock<FirewireOmniStats> stats_;
  Seqlock<StatePacket> last_;
  std::atomic<bool> calibrated_{false};
  // servo thread's own
  std::array<std::uint8_t, 64> rx_{};  // one received packet (> 44 bytes, so
                                       // a long one arrives whole)
  FirewireOmniStats s_;
  OmniCalibration cal_local_;
  std::uint64_t cal_local_gen_ = 0;
  bool have_counts_ = false;
  std::array<std::int32_t, 3> counts_{};
  bool have_counter_ = false;
  bool was_docked_ = false;
  bool motors_on_ = false;

  DeviceError send_command(const CommandPacket& c) noexcept;
  void publish() noexcept { stats_.write(s_); }
  // read_state()'s steps (firewire_omni.cc says each)
  DeviceError receive_failed(TransportStatus ts) noexcept;
  void count_packet(const StatePacket& p, const ReceiveInfo& info) noexcept;
  void unwrap_counts(const StatePacket& p) noexcept;
  bool take_calibration(bool docked) noexcept;
  DeviceError fill_state(const StatePacket& p, bool docked, bool rehomed,
                         DeviceState* state) noexcept;
};

// The backend: owns the transport and the device, runs the loop on the
// project's ServoThread (device/servo_thread.h).
class FirewireBackend final : public DeviceBackend {
 public:
  // `identity` fills what the transport does not know (backend name,
  // config). Throws std::invalid_argument for bad options.
  // `lockstep` (not owned; may be null): the simulated plant on the other
  // end of the transport (the emulator behind the packets), which lets
  // the loop run in lockstep (ServoOptions::lockstep, device/lockstep.h);
  // without it a lockstep start is refused.
  FirewireBackend(std::unique_ptr<Transport> transport,
                  const FirewireOmniOptions& options,
                  DeviceIdentity identity,
                  LockstepPlant* lockstep = nullptr);
  ~FirewireBackend() override;

  DeviceIdentity identity() const override;
  CalibrationState calibration_state() override;
  HapticDevice* device() noexcept override { return &omni_; }
  ServoReport start(ServoLoop* loop, const ServoOptions& options) override;
  void stop() noexcept override;
  bool running() const noexcept override;
  TickStats timing() const override;
  void pass(double dt_s) override;

  FirewireOmni* omni() noexcept { return &omni_; }
  Transport* transport() noexcept { return transport_.get(); }

 private:
  std::unique_ptr<Transport> transport_;
  FirewireOmni omni_;
  DeviceIdentity identity_;
  std::unique_ptr<ServoThread> thread_;
  LockstepPlant* plant_ = nullptr;
  std::unique_ptr<LockstepDriver> lockstep_;
  bool started_ = false;
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_FIREWIRE_OMNI_H_
