// The servo chain: the one place where a servo tick is assembled, for the
// simulated closed loop (sim/closed_loop.h) and for a session on a device
// (runtime/session.h) alike:
//
//   command source (controller / zero / a torque pulse)
//     -> [SafetyLayer]   (device/safety.h; optional: always on a device,
//                         an option in simulation)
//     -> ReadingGuard    (device/reading_guard.h)
//     -> the device      (any HapticDevice: SimDevice, a backend's device)
//
// Each tick reads the device's whole state once through the chain, runs
// the command source on it, writes the torque (zero after a failed read or
// a controller fault: servo_tick's rule, device/servo_tick.h) and fills a
// TickRecord (device/tick_record.h) with what it saw and did. The plant's
// truth, when there is one, is the caller's to add.
//
// tick() allocates nothing, takes no lock and throws nothing
// (tests/device/servo_chain_test.cc counts allocations).
#ifndef VMHAPTICS_DEVICE_SERVO_CHAIN_H_
#define VMHAPTICS_DEVICE_SERVO_CHAIN_H_

#include <memory>
#include <optional>

#include "controller/controller.h"
#include "controller/omni_params.h"
#include "device/haptic_device.h"
#include "device/reading_guard.h"
#include "device/safety.h"
#include "device/tick_record.h"

namespace vmh {

// What commands the motors.
enum class ChainMode {
  kRun,        // the controller (ChainOptions::controller)
  kRecord,     // nothing: zero torque, the readings recorded
  kMotorTest,  // one torque pulse on one motor (ChainOptions::pulse)
};

// motor-test: torque_Nm on `motor` (1..3) from start_s for length_s of the
// chain's time, zero before and after
struct MotorPulse {
  int motor = 1;
  double torque_Nm = 0.0;
  double start_s = 0.5;
  double length_s = 0.0;
};

struct ChainOptions {
  ChainMode mode = ChainMode::kRun;
  GuardParams guard;
  // the safety layer between the command and the guard; its omni is
  // ChainOptions::omni
  bool safety = true;
  SafetyParams safety_params;
  // the device's geometry, for the safety layer and the reading's pose
  // (the controller's own when there is one)
  OmniParams omni;
  // kRun: the controller, and optionally a reference gain set evaluated on
  // every reading without acting (TickRecord::force_reference_N)
  std::optional<ControllerParams> controller;
  std::optional<ControllerParams> reference;
  MotorPulse pulse;  // kMotorTest
};

// The safety layer's limits for a controller's device, as `hw run` and the
// simulated loop behind the safety layer (the case's safety_layer) use
// them: SafetyParams' defaults with the controller's servo period and its
// motor torque limits (the case's torque_limits).
SafetyParams safety_params_for(const ControllerParams& params);

class ServoChain {
 public:
  // `device` is not owned and must outlive the chain. Throws
  // std::invalid_argument naming what is wrong (kRun without a controller,
  // a pulse on a motor outside 1..3, a bad guard, safety or controller
  // parameter).
  ServoChain(HapticDevice* device, const ChainOptions& options);
  ~ServoChain();
  ServoChain(const ServoChain&) = delete;
  ServoChain& operator=(const ServoChain&) = delete;

  // One tick at the chain's time t_s (what the pulse and the record go
  // by; period_s is set to the time since the previous tick, which the
  // loop replaces with the tick's own length once it knows it) and the clock's
  // reading now_s (the safety layer's time stamp; the same clock on every
  // tick). Fills every field of *rec the chain knows and clears the
  // truth flag (has_truth = false).
  void tick(double t_s, double now_s, TickRecord* rec) noexcept;

  // adds (or replaces) the reference gain set (ChainOptions::reference)
  // without touching the rest; not while a tick runs
  void set_reference(const ControllerParams& params);

  // back to the state before the first tick: controller, guard latch,
  // the safety layer (ramp from zero), the period's reference
  void reset();

  // the chain's top: what servo_tick talks to (the safety layer, or the
  // guard without it)
  HapticDevice* top() noexcept;
  ReadingGuard& guard() noexcept { return *guard_; }
  SafetyLayer* safety() noexcept { return safety_.get(); }
  const Controller* controller() const noexcept { return controller_.get(); }
  const ChainOptions& options() const noexcept { return options_; }

 private:
  void command_without_controller(double t_s, TickRecord* rec) noexcept;

  HapticDevice* device_;
  ChainOptions options_;
  std::unique_ptr<ReadingGuard> guard_;
  std::unique_ptr<SafetyLayer> safety_;
  std::unique_ptr<Controller> controller_;
  std::unique_ptr<Controller> reference_;
  ControlOutput reference_out_;
  double length_unit_mm_ = 1.0;
  bool have_last_ = false;
  double last_t_s_ = 0.0;
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SERVO_CHAIN_H_
