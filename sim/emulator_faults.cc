// The emulator's hand programs' names, and its transport faults
// (sim/emulator_faults.h) from their text form (sim/fault_vocabulary.h
// parses it).
#include "sim/emulator_faults.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/emulator.h"
#include "sim/fault_vocabulary.h"

namespace vmh::sim {
namespace {

struct ProgramName {
  HandProgram program;
  const char* name;
};
constexpr ProgramName kPrograms[] = {
    {HandProgram::kCase, "case"},
    {HandProgram::kTour, "tour"},
    {HandProgram::kNone, "none"},
    {HandProgram::kDock, "dock"},
    {HandProgram::kGimbalSweep, "gimbal_sweep"},
    {HandProgram::kManual, "manual"},
};

}  // namespace

const char* hand_program_name(HandProgram p) {
  for (const ProgramName& n : kPrograms) {
    if (n.program == p) return n.name;
  }
  return "unknown";
}

HandProgram parse_hand_program(const std::string& name) {
  for (const ProgramName& n : kPrograms) {
    if (name == n.name) return n.program;
  }
  throw std::invalid_argument("unknown hand program '" + name +
                              "' (case, tour, none, dock, gimbal_sweep, manual)");
}

const char* emulator_fault_name(EmulatorFaultKind k) {
  switch (k) {
    case EmulatorFaultKind::kDrop: return "drop";
    case EmulatorFaultKind::kLate: return "late";
    case EmulatorFaultKind::kStall: return "stall";
    case EmulatorFaultKind::kUnplug: return "unplug";
  }
  return "unknown";
}

// Throws std::invalid_argument naming the fault and its bad field.
void validate_emulator_fault(const EmulatorFault& f) {
  const std::string name = emulator_fault_name(f.kind);
  if (!std::isfinite(f.at_s) || f.at_s < 0.0) {
    throw std::invalid_argument("emulator fault " + name +
                                ": at_s must be finite and >= 0");
  }
  switch (f.kind) {
    case EmulatorFaultKind::kDrop:
      if (f.count < 1) {
        throw std::invalid_argument("emulator fault drop: count must be >= 1");
      }
      return;
    case EmulatorFaultKind::kLate:
      if (f.count < 1 || f.count > kMaxLatePeriods) {
        throw std::invalid_argument(
            "emulator fault late: count must be in [1, " +
            std::to_string(kMaxLatePeriods) + "] periods");
      }
      break;
    case EmulatorFaultKind::kStall:
    case EmulatorFaultKind::kUnplug:
      break;
  }
  if (!std::isfinite(f.duration_s) || f.duration_s <= 0.0) {
    throw std::invalid_argument("emulator fault " + name +
                                ": duration_s must be finite and > 0");
  }
}

std::vector<EmulatorFault> parse_emulator_faults(const std::string& text) {
  std::vector<EmulatorFault> out;
  for (const FaultItem& it : parse_faults(text, kTransportFaults)) {
    EmulatorFault f;
    const std::string kind = it.kind->name;
    f.at_s = it.at_s;
    if (kind == "drop") {
      f.kind = EmulatorFaultKind::kDrop;
      f.count = static_cast<int>(it.values[0]);
    } else if (kind == "late") {
      f.kind = EmulatorFaultKind::kLate;
      f.duration_s = it.values[0];
      f.count = static_cast<int>(it.values[1]);
    } else if (kind == "stall") {
      f.kind = EmulatorFaultKind::kStall;
      f.duration_s = it.values[0];
    } else {  // the table's last transport kind
      f.kind = EmulatorFaultKind::kUnplug;
      f.duration_s = it.values[0];
    }
    try {
      validate_emulator_fault(f);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("emulator fault '" + it.text + "': " + e.what());
    }
    out.push_back(f);
  }
  return out;
}

}  // namespace vmh::sim
