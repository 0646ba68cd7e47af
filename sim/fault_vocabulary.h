// Every fault the testbed can inject, in one table with one grammar and one
// parser, for the four places that take them:
//
//   sensor     the case's `fault` field (sim/fault_injector.h): a joint's
//              sensor reads nan, jumps by 1000 counts, or sticks; its
//              joint and time are the case fields fault_joint, fault_at_s
//   transport  `--fault` on the emulator (sim/emulator_faults.h,
//              EmulatorFault): reads dropped, late, a stalled physics, an
//              unplug
//   wire       `--fault` on emulator:firewire (sim/emulator_firewire.h,
//              WireFault): packets lost, late, of the wrong length, a bus
//              reset, an unplug, a stall
//   seeded     `--emulator-fault` (sim/emulator_faults.h, SeededFaults): a
//              mistake built into the emulated device for a whole session,
//              for bring-up's `compare` to find
//
// Two forms, told apart by '@':
//   timed:  KIND@AT_S[:FIELD...], e.g. drop@1.0:5, late@2:0.5:3, reset@4
//           (AT_S in emulator time from the start, s)
//   named:  a name whose <X> parts are numbers, e.g. joint2_sign,
//           link_length_-1.5pct, mass_x2
// A list is comma-separated; spaces are ignored. Every refusal is a
// std::invalid_argument naming the item, what was wrong and the kinds there
// are, as `<layer> fault '<item>': <why> (<kinds>)`.
#ifndef VMHAPTICS_SIM_FAULT_VOCABULARY_H_
#define VMHAPTICS_SIM_FAULT_VOCABULARY_H_

#include <string>
#include <vector>

namespace vmh::sim {

enum FaultLayer : unsigned {
  kSensorFaults = 1u << 0,
  kTransportFaults = 1u << 1,
  kWireFaults = 1u << 2,
  kSeededFaults = 1u << 3,
};

// one number of a fault: its name (as messages and help give it), unit and
// range; whole: a whole number
struct FaultField {
  const char* name;
  const char* unit;
  double lo;
  double hi;
  bool whole = false;
  bool lo_open = false;  // lo itself is refused (> lo)
};

struct FaultKind {
  // timed: the kind's name ("drop"); named: its pattern ("joint<N>_sign",
  // "mass_x<K>"), whose one <X> part is `fields[0]`
  const char* name;
  unsigned layers;  // FaultLayer bits: where it may be given
  bool timed;
  std::vector<FaultField> fields;
  const char* doc;  // what it does, one line
  // named kinds that may be given once only share a `group` ("torque_units"
  // for both units mistakes); empty: the name itself
  const char* group = "";
};

// The table.
const std::vector<FaultKind>& fault_kinds();

// One item as parsed: its kind, its text (spaces removed), its time (timed
// kinds) and its fields' values in the table's order (for a named kind,
// the number in its pattern).
struct FaultItem {
  const FaultKind* kind = nullptr;
  std::string text;
  double at_s = 0.0;
  std::vector<double> values;
};

// Parses a comma-separated list of the kinds `layer` takes. Empty text (or
// only spaces): none. Named kinds may each be given once (per group).
// Throws std::invalid_argument as the file comment says.
std::vector<FaultItem> parse_faults(const std::string& text, FaultLayer layer);

// The kinds a layer takes, in their written form: "drop@t:N, late@t:dur:K,
// ..." (timed) or "joint<N>_sign, gimbal_swap, ..." (named)
std::string fault_forms(FaultLayer layer);
// "drop@t:N (the next N reads time out), ...": for --help
std::string fault_help(FaultLayer layer);
// "sensor", "emulator", "firewire", "seeded emulator": in messages
const char* fault_layer_name(FaultLayer layer);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_FAULT_VOCABULARY_H_
