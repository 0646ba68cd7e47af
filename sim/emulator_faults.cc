// The emulator's names and the fault list's text form (sim/emulator.h).
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/emulator.h"

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
};

double number(const std::string& text, const std::string& item,
              const char* what) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
    throw std::invalid_argument("emulator fault '" + item + "': " + what +
                                " '" + text + "' is not a number");
  }
  return v;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else if (c != ' ') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

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
                              "' (case, tour, none, dock, gimbal_sweep)");
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
  if (text.find_first_not_of(' ') == std::string::npos) return out;
  for (const std::string& item : split(text, ',')) {
    const auto at = item.find('@');
    if (at == std::string::npos) {
      throw std::invalid_argument("emulator fault '" + item +
                                  "': expected kind@at_s[:...]");
    }
    const std::string kind = item.substr(0, at);
    const std::vector<std::string> f = split(item.substr(at + 1), ':');
    EmulatorFault fault;
    std::size_t want = 0;
    if (kind == "drop") {
      fault.kind = EmulatorFaultKind::kDrop;
      want = 2;
    } else if (kind == "late") {
      fault.kind = EmulatorFaultKind::kLate;
      want = 3;
    } else if (kind == "stall") {
      fault.kind = EmulatorFaultKind::kStall;
      want = 2;
    } else if (kind == "unplug") {
      fault.kind = EmulatorFaultKind::kUnplug;
      want = 2;
    } else {
      throw std::invalid_argument("emulator fault '" + item + "': unknown kind '" +
                                  kind + "' (drop, late, stall, unplug)");
    }
    if (f.size() != want) {
      throw std::invalid_argument(
          "emulator fault '" + item + "': " + kind + " takes " +
          (kind == "drop"   ? "at_s:count"
           : kind == "late" ? "at_s:duration_s:count"
                            : "at_s:duration_s"));
    }
    fault.at_s = number(f[0], item, "at_s");
    if (fault.kind == EmulatorFaultKind::kDrop) {
      const double c = number(f[1], item, "count");
      if (c != std::floor(c) || c < 1 || c > 1e6) {
        throw std::invalid_argument("emulator fault '" + item +
                                    "': count must be a whole number >= 1");
      }
      fault.count = static_cast<int>(c);
    } else {
      fault.duration_s = number(f[1], item, "duration_s");
    }
    if (fault.kind == EmulatorFaultKind::kLate) {
      const double c = number(f[2], item, "count");
      if (c != std::floor(c) || c < 1 || c > kMaxLatePeriods) {
        throw std::invalid_argument("emulator fault '" + item +
                                    "': count must be a whole number in [1, " +
                                    std::to_string(kMaxLatePeriods) + "]");
      }
      fault.count = static_cast<int>(c);
    }
    try {
      validate_emulator_fault(fault);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("emulator fault '" + item + "': " + e.what());
    }
    out.push_back(fault);
  }
  return out;
}

}  // namespace vmh::sim
