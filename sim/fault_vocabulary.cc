#include "sim/fault_vocabulary.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace vmh::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// the emulator's late ring (sim/emulator_faults.h, kMaxLatePeriods) and
// the most packets a loss or length fault may take
// (kMaxWireLengthFaultPackets)
constexpr double kMaxLate = 63;
constexpr double kMaxPackets = 1e6;

const FaultField kCount{"count", "N", 1, kMaxPackets, true};
const FaultField kDuration{"duration_s", "dur", 0, kInf, false, true};
const FaultField kPeriods{"count", "K", 1, kMaxLate, true};

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// "a whole number in [1, 63]", "> 0", "in (-50, 100)"
std::string rule(const FaultField& f) {
  if (f.whole) return "a whole number in [" + num(f.lo) + ", " + num(f.hi) + "]";
  if (std::isinf(f.hi)) return std::string(f.lo_open ? "> " : ">= ") + num(f.lo);
  return std::string("in ") + (f.lo_open ? "(" : "[") + num(f.lo) + ", " +
         num(f.hi) + (f.lo_open ? ")" : "]");
}

bool starts_with(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(0, p.size(), p) == 0;
}
bool ends_with(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(s.size() - p.size(), p.size(), p) == 0;
}

// a named kind's pattern split at its <X>: prefix, suffix (no <X>: the
// whole name is the prefix and has_field is false)
struct Pattern {
  std::string prefix, suffix;
  bool has_field = false;
};
Pattern split_pattern(const char* name) {
  const std::string s = name;
  const auto open = s.find('<');
  if (open == std::string::npos) return {s, "", false};
  const auto close = s.find('>', open);
  return {s.substr(0, open), s.substr(close + 1), true};
}

}  // namespace

const std::vector<FaultKind>& fault_kinds() {
  static const std::vector<FaultKind> kinds = {
      // the sensor injector (the case's fault, fault_joint, fault_at_s)
      {"nan", kSensorFaults, false, {}, "the joint reads NaN"},
      {"jump", kSensorFaults, false, {},
       "an encoder reads 1000 counts high from then on (a count slip)"},
      {"stuck", kSensorFaults, false, {}, "the joint keeps its reading"},
      // the emulator's transport and the FireWire packets
      {"drop", kTransportFaults, true, {kCount}, "the next N reads time out"},
      {"loss", kWireFaults, true, {kCount},
       "the next N state packets never arrive"},
      {"late", kTransportFaults | kWireFaults, true, {kDuration, kPeriods},
       "for dur s every reading is K servo periods old"},
      {"length", kWireFaults, true, {kCount},
       "the next N packets arrive 43 and 45 bytes long"},
      {"reset", kWireFaults, true, {}, "a bus reset (recovered by the driver)"},
      {"stall", kTransportFaults | kWireFaults, true, {kDuration},
       "the device's physics freezes for dur s (reads time out)"},
      {"unplug", kTransportFaults | kWireFaults, true, {kDuration},
       "the device is gone for dur s (not_connected, zero torque held), then "
       "back"},
      // seeded mistakes of the emulated device or the host's view of it
      {"joint<N>_sign", kSeededFaults, false, {{"N", "", 1, 6, true}},
       "the reported t_N is negated after decoding"},
      {"gimbal_swap", kSeededFaults, false, {},
       "the reported t5 and t6 are swapped after decoding"},
      {"link_length_<P>pct", kSeededFaults, false,
       {{"P", "%", -50, 100, false, true}},
       "the real l1 is P % longer", "link_length"},
      {"delay_<M>ms", kSeededFaults, false, {{"M", "ms", 0, kInf, false, true}},
       "every reading is M ms late (whole servo periods)", "delay"},
      {"motor3_relative", kSeededFaults, false, {},
       "motor 3 turns the relative elbow angle q3"},
      {"motor<N>_sign", kSeededFaults, false, {{"N", "", 1, 3, true}},
       "motor N turns the other way"},
      {"torque_units_Nm", kSeededFaults, false, {},
       "each written torque taken 1000x (mN m read as N m)", "torque_units"},
      {"torque_units_mNm", kSeededFaults, false, {},
       "each written torque taken 0.001x", "torque_units"},
      {"mass_x<K>", kSeededFaults, false, {{"K", "", 0, kInf, false, true}},
       "the Omni's masses and inertias times K", "mass"},
      {"friction_x<K>", kSeededFaults, false, {{"K", "", 0, kInf, false, true}},
       "joint dry friction times K", "friction"},
      {"damping_x<K>", kSeededFaults, false, {{"K", "", 0, kInf, false, true}},
       "joint damping times K", "damping"},
  };
  return kinds;
}

const char* fault_layer_name(FaultLayer layer) {
  switch (layer) {
    case kSensorFaults: return "sensor";
    case kTransportFaults: return "emulator";
    case kWireFaults: return "firewire";
    case kSeededFaults: return "seeded emulator";
  }
  return "?";
}

namespace {

// a kind as it is written: its name, and for a timed kind @t and its fields
std::string written_form(const FaultKind& k) {
  std::string form = k.name;
  if (k.timed) {
    form += "@t";
    for (const FaultField& f : k.fields) form += std::string(":") + f.unit;
  }
  return form;
}

// the written forms of a layer's kinds, each followed by `more(kind)`,
// joined by `sep`
template <typename More>
std::string list_kinds(FaultLayer layer, const char* sep, More more) {
  std::string s;
  for (const FaultKind& k : fault_kinds()) {
    if (!(k.layers & layer)) continue;
    s += (s.empty() ? "" : sep) + written_form(k) + more(k);
  }
  return s;
}

}  // namespace

std::string fault_forms(FaultLayer layer) {
  return list_kinds(layer, ", ", [](const FaultKind&) { return std::string(); });
}

std::string fault_help(FaultLayer layer) {
  return list_kinds(layer, "; ",
                    [](const FaultKind& k) { return std::string(": ") + k.doc; });
}

namespace {

// The items of a fault list, split at its commas with the spaces dropped
// (empty items kept: parse_faults names them)
std::vector<std::string> fault_items(const std::string& text) {
  std::vector<std::string> items;
  std::string cur;
  for (char c : text + ",") {
    if (c == ' ') continue;
    if (c != ',') {
      cur += c;
      continue;
    }
    items.emplace_back();
    items.back().swap(cur);
  }
  return items;
}

// Throws std::invalid_argument for one item: "<layer> fault '<item>':
// <why> (<the layer's forms>)"
struct ItemFail {
  const std::string& what;
  const std::string& item;
  const std::string& forms;
  [[noreturn]] void operator()(const std::string& why) const {
    throw std::invalid_argument(what + item + "': " + why + forms);
  }
};

// kind@at_s[:field...]: the kind's name into *name, and at_s and the
// fields, split at ':', into *parts
void split_timed(const std::string& item, const ItemFail& fail,
                 std::string* name, std::vector<std::string>* parts) {
  const auto at = item.find('@');
  if (at == std::string::npos) fail("expected kind@at_s[:...]");
  *name = item.substr(0, at);
  std::string rest = item.substr(at + 1) + ":";
  std::string p;
  for (char d : rest) {
    if (d == ':') {
      parts->push_back(p);
      p.clear();
    } else {
      p += d;
    }
  }
}

// The layer's kind that `name` is: a timed kind by its name, a named kind
// by its pattern (the text of its <X> into *middle); nullptr if none
const FaultKind* find_kind(const std::string& name, FaultLayer layer,
                           bool timed_layer, std::string* middle) {
  const FaultKind* kind = nullptr;
  for (const FaultKind& k : fault_kinds()) {
    if (!(k.layers & layer) || k.timed != timed_layer) continue;
    if (k.timed) {
      if (name == k.name) kind = &k;
    } else {
      const Pattern pat = split_pattern(k.name);
      if (!pat.has_field) {
        if (name == pat.prefix) kind = &k;
      } else if (name.size() > pat.prefix.size() + pat.suffix.size() &&
                 starts_with(name, pat.prefix) && ends_with(name, pat.suffix)) {
        // the longest fixed text wins (motor3_relative is not motor<N>_sign)
        kind = &k;
        *middle =
            name.substr(pat.prefix.size(),
                        name.size() - pat.prefix.size() - pat.suffix.size());
      }
    }
    if (kind != nullptr) break;
  }
  return kind;
}

// v read as a number into *x: false unless all of v is one, finite
bool read_number(const std::string& v, double* x) {
  char* end = nullptr;
  *x = std::strtod(v.c_str(), &end);
  return !v.empty() && end == v.c_str() + v.size() && std::isfinite(*x);
}

// The text of each of kind k's fields: a timed kind's after its at_s
// (their count checked, at_s read into it->at_s), a named kind's <X>
std::vector<std::string> field_texts(const FaultKind& k,
                                     const std::vector<std::string>& parts,
                                     const std::string& middle,
                                     const ItemFail& fail, FaultItem* it) {
  std::vector<std::string> values;
  if (k.timed) {
    if (parts.size() != 1 + k.fields.size()) {
      fail(std::string(k.name) + " takes " + written_form(k));
    }
    values.assign(parts.begin() + 1, parts.end());
    if (!read_number(parts[0], &it->at_s)) {
      fail("at_s '" + parts[0] + "' is not a number");
    }
    if (it->at_s < 0.0) fail("at_s '" + parts[0] + "' must be >= 0");
  } else if (!k.fields.empty()) {
    values.push_back(middle);
  }
  return values;
}

// field f's value v, a number that keeps f's rule (rule(f))
double field_value(const FaultField& f, const std::string& v,
                   const ItemFail& fail) {
  double x = 0.0;
  if (!read_number(v, &x)) {
    fail(std::string(f.name) + " '" + v + "' is not a number");
  }
  const bool whole_ok = !f.whole || x == std::floor(x);
  const bool lo_ok = f.lo_open ? x > f.lo : x >= f.lo;
  const bool hi_ok =
      std::isinf(f.hi) || (f.lo_open && !f.whole ? x < f.hi : x <= f.hi);
  if (!whole_ok || !lo_ok || !hi_ok) {
    fail(std::string(f.name) + " '" + v + "' must be " + rule(f));
  }
  return x;
}

// One item of the layer: its kind, at_s and field values. A named kind's
// group must not be in *groups yet, and is added to it.
FaultItem parse_item(const std::string& item, FaultLayer layer,
                     const ItemFail& fail, std::vector<std::string>* groups) {
  const bool timed_layer = layer == kTransportFaults || layer == kWireFaults;
  FaultItem it;
  it.text = item;
  std::string name = item;
  std::vector<std::string> parts;  // timed: at_s, then the fields
  if (timed_layer) split_timed(item, fail, &name, &parts);
  std::string middle;
  it.kind = find_kind(name, layer, timed_layer, &middle);
  if (it.kind == nullptr) {
    fail(timed_layer ? "unknown kind '" + name + "'" : "unknown name");
  }
  const FaultKind& k = *it.kind;
  const std::vector<std::string> values =
      field_texts(k, parts, middle, fail, &it);
  for (std::size_t i = 0; i < k.fields.size(); ++i) {
    it.values.push_back(field_value(k.fields[i], values[i], fail));
  }
  if (!k.timed) {
    const std::string group = k.group[0] != '\0' ? k.group : name;
    for (const std::string& g : *groups) {
      if (g == group) fail(group + " given twice");
    }
    groups->push_back(group);
  }
  return it;
}

}  // namespace

std::vector<FaultItem> parse_faults(const std::string& text, FaultLayer layer) {
  std::vector<FaultItem> out;
  const std::string what = std::string(fault_layer_name(layer)) + " fault '";
  const std::string forms = " (" + fault_forms(layer) + ")";
  if (text.find_first_not_of(" ,") == std::string::npos) return out;
  std::vector<std::string> groups;  // named kinds given so far
  for (const std::string& item : fault_items(text)) {
    const ItemFail fail{what, item, forms};
    if (item.empty()) fail("empty item in '" + text + "'");
    out.push_back(parse_item(item, layer, fail, &groups));
  }
  return out;
}

}  // namespace vmh::sim
