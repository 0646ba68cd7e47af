// The emulator's faults (sim/emulator.h): the transport faults scheduled
// on its clock (a read dropped, a late reading, a stall, an unplug) and the
// seeded faults, mistakes built into the emulated device for bring-up to
// find; their names and their text form (the one grammar and table of
// sim/fault_vocabulary.h). emulator_faults.cc and emulator_seeded.cc
// implement them.
#ifndef VMHAPTICS_SIM_EMULATOR_FAULTS_H_
#define VMHAPTICS_SIM_EMULATOR_FAULTS_H_

#include <array>
#include <string>
#include <vector>

#include "controller/types.h"
#include "sim/omni_model_edit.h"

namespace vmh::sim {

enum class EmulatorFaultKind {
  kDrop,    // the next `count` reads return kTimeout
  kLate,    // for duration_s, reads return a snapshot `count` periods old
  kStall,   // the physics freezes for duration_s (reads time out)
  kUnplug,  // for duration_s reads and writes return kNotConnected, zero
            // torque held; then replugged
};
const char* emulator_fault_name(EmulatorFaultKind k);  // "drop", ...

struct EmulatorFault {
  EmulatorFaultKind kind = EmulatorFaultKind::kDrop;
  double at_s = 0.0;        // emulator time from start()
  double duration_s = 0.0;  // late, stall, unplug
  int count = 0;            // drop: reads; late: periods (1..kMaxLatePeriods)
};
inline constexpr int kMaxLatePeriods = 63;

// Seeded faults: a mistake built into the emulated device (or into the
// host's view of it) for the whole session, for bring-up's `compare` to
// find. Hidden: nothing a session writes to its trace carries them; meta.json
// records them only under "emulator" (the emulator's setup, for tests).
// Text form (parse_seeded_faults; the names are the seeded kinds of
// sim/fault_vocabulary.h's table), comma-separated, combinable:
//   joint<N>_sign       N = 1..6: the reported t_N is negated after decoding
//                       (a sign mistake in the host's codec or wiring); the
//                       raw encoder counts and pot codes and the device's own
//                       transform, velocity and Jacobian stay true
//   gimbal_swap         the reported t5 and t6 swapped after decoding (a
//                       pots' wiring mistake); raw values and kinematics
//                       stay true. The tour keeps |t6| < 0.9 rad and t5 in
//                       [0.05, 0.91] rad (measured on case1), inside t5's
//                       +-1.13 and t6's +-2.58 rad, so the swapped readings
//                       pass the reading guard; kGimbalSweep's do not
//   link_length_<P>pct  the real l1 is P % longer (P may be negative or
//                       decimal): physics and the reported transform use it
//   delay_<M>ms         every reading (every field, timestamp too) is M ms
//                       late: a whole number of servo periods, at most
//                       kMaxLatePeriods
//   motor3_relative     motor 3 turns the relative elbow angle q3
//   motor<N>_sign       N = 1..3: that motor turns the other way
//   torque_units_Nm     each written torque taken 1000x (mN m read as N m;
//                       the motors' clamps then limit it)
//   torque_units_mNm    each written torque taken 0.001x
//   mass_x<K>, friction_x<K>, damping_x<K>   K > 0: the Omni's masses and
//                       inertias, joint dry friction, joint damping times K
struct SeededFaults {
  std::array<bool, 6> joint_sign{};  // reported t1..t6 negated
  bool gimbal_swap = false;          // reported t5 <-> t6
  double delay_ms = 0.0;             // 0: none
  double torque_scale = 1.0;         // applied to each written torque
  OmniModelEdit edit;                // link_length, motor*, mass, ...
  std::vector<std::string> items;    // the list as given, in order

  bool any() const { return !items.empty(); }
};
// Throws std::invalid_argument naming the bad item and listing the names.
SeededFaults parse_seeded_faults(const std::string& text);
// The reported joint angles as the seeded faults make them (device
// convention, rad). Real-time: no allocation.
void apply_seeded_readings(const SeededFaults& seeded,
                           Joints* q_device_rad) noexcept;

// "drop@1.0:5,late@2.0:0.5:3,stall@3:0.2,unplug@4:1": kind@at_s then
// drop:count, late:duration_s:count, stall:duration_s, unplug:duration_s
// (the one fault grammar and table: sim/fault_vocabulary.h). Empty text:
// no faults. Throws std::invalid_argument naming the bad item.
std::vector<EmulatorFault> parse_emulator_faults(const std::string& text);
// Throws std::invalid_argument naming the fault's bad field.
void validate_emulator_fault(const EmulatorFault& fault);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_FAULTS_H_
