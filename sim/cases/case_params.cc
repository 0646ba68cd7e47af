#include "sim/cases/case_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "controller/virtual_mechanism.h"
#include "sim/cases/case_params_detail.h"

namespace vmh::sim {

namespace detail {

int word_index(const char* words, const std::string& text) {
  std::istringstream in(std::string(words == nullptr ? "" : words));
  std::string w;
  int i = 0;
  while (std::getline(in, w, ',')) {
    const auto b = w.find_first_not_of(' ');
    if (b != std::string::npos && w.substr(b) == text) return i;
    ++i;
  }
  return -1;
}

std::string format_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace detail

using detail::format_number;
using detail::word_index;

namespace {

std::string join_words(const std::string& a, const std::string& b) {
  return a.empty() ? b : a + ", " + b;
}

// "1,2,3" or "1 2 3" -> numbers; false on anything that is not a number
bool parse_numbers(const std::string& text, std::vector<double>* out) {
  std::string s = text;
  std::replace(s.begin(), s.end(), ',', ' ');
  std::istringstream in(s);
  std::string token;
  out->clear();
  while (in >> token) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') return false;
    out->push_back(v);
  }
  return true;
}

std::size_t row_of(const ParamSpec& spec) {
  return static_cast<std::size_t>(&spec - case_fields().data());
}

// A row the loader itself needs by name (a typo here is a bug, caught by
// every load in the tests, not a user's mistake).
const ParamSpec& row_named(const char* name) {
  const ParamSpec* f = find_param(name);
  if (f == nullptr) throw std::logic_error(std::string("no parameter ") + name);
  return *f;
}

// "<where>: field '<name>'", the start of every message about a value
std::string field_at(const ParamSpec& spec, const ParamValue& v) {
  return v.where + ": field '" + spec.name + "'";
}

// Parses `text` into the row's value; throws naming `where` and the field.
void store(const ParamSpec& spec, const std::string& text, ValueSource from,
           const std::string& where, ParamValue* v) {
  ParamValue out;
  out.source = from;
  out.where = where;
  out.set = true;
  if (spec.is_text) {
    out.text = text;
  } else {
    if (!parse_numbers(text, &out.numbers)) {
      throw ParamError(where + ": field '" + spec.name +
                       "' expects numbers, got '" + text + "'");
    }
    if (static_cast<int>(out.numbers.size()) != spec.size) {
      throw ParamError(where + ": field '" + spec.name + "' expects " +
                       std::to_string(spec.size) + " value(s), got " +
                       std::to_string(out.numbers.size()));
    }
    for (double x : out.numbers) {
      const bool ok = std::isfinite(x) || (spec.allow_inf && x > 0.0);
      if (!ok) {
        throw ParamError(where + ": field '" + spec.name + "' is not finite" +
                         (spec.allow_inf ? " (+inf is allowed)" : ""));
      }
    }
  }
  *v = std::move(out);
}

// The row's own rule (range, whole number, word) on every item.
void check_rule(const ParamSpec& spec, const ParamValue& v) {
  if (spec.is_text) {
    if (word_index(spec.words, v.text) < 0) {
      throw ParamError(v.where + ": unknown value '" + v.text +
                       "' (expected one of: " + spec.words + ") for field '" +
                       spec.name + "'");
    }
    return;
  }
  for (double x : v.numbers) check_param_number(spec, x, v.where);
}

}  // namespace

const char* value_source_name(ValueSource s) {
  switch (s) {
    case ValueSource::kDefault: return "default";
    case ValueSource::kScene: return "scene";
    case ValueSource::kOverride: return "set";
  }
  return "unknown";
}

const ParamValue& CaseParams::value(const ParamSpec& spec) const {
  return values.at(row_of(spec));
}

const ParamSpec* find_param(const std::string& name) {
  for (const ParamSpec& f : case_fields()) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

std::string param_names() {
  std::string all;
  for (const ParamSpec& f : case_fields()) all = join_words(all, f.name);
  return all;
}

void check_param_number(const ParamSpec& spec, double x,
                        const std::string& where) {
  bool ok = true;
  switch (spec.rule) {
    case ParamRule::kAny: break;
    case ParamRule::kPositive: ok = x > 0.0; break;
    case ParamRule::kNonNegative: ok = x >= 0.0; break;
    case ParamRule::kWhole:
      ok = x == std::floor(x) && x >= spec.lo && x <= spec.hi;
      break;
    case ParamRule::kInRange: ok = x >= spec.lo && x <= spec.hi; break;
  }
  if (spec.has_max && !(x <= spec.hi)) ok = false;
  if (!ok) {
    throw ParamError(where + ": field '" + spec.name + "' must be " +
                     spec.rule_text() + ", got " + format_number(x));
  }
}

std::string ParamSpec::rule_text() const {
  if (is_text) return "";
  std::string r;
  switch (rule) {
    case ParamRule::kAny: return "";
    case ParamRule::kPositive: r = "> 0"; break;
    case ParamRule::kNonNegative: r = allow_inf ? ">= 0, or inf" : ">= 0"; break;
    case ParamRule::kWhole:
      return lo == 0 && hi == 1 ? std::string("0 or 1")
                                : "a whole number in [" + format_number(lo) +
                                      ", " + format_number(hi) + "]";
    case ParamRule::kInRange:
      return "in [" + format_number(lo) + ", " + format_number(hi) + "]";
  }
  if (has_max) r += " and <= " + format_number(hi);
  return r;
}

std::string ParamSpec::range_text() const {
  std::string r;
  if (is_text) {
    r = words;
  } else {
    r = rule == ParamRule::kAny ? "any" : rule_text();
    if (size > 1 && rule != ParamRule::kAny) r = "each " + r;
  }
  if (range_note != nullptr) r += "; " + std::string(range_note);
  return r;
}

std::string ParamSpec::default_text() const {
  std::string d = default_value != nullptr ? default_value : "(required)";
  if (surface_default != nullptr) {
    d += " (surface: " + std::string(surface_default) + ")";
  }
  if (ctl_default != nullptr) d += " (ctl: " + std::string(ctl_default) + ")";
  return d;
}

std::vector<ParamInput> set_inputs(const std::vector<std::string>& sets) {
  std::vector<ParamInput> inputs;
  for (const std::string& o : sets) {
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw ParamError("--set '" + o + "': expected name=value");
    }
    const std::string name = o.substr(0, eq);
    if (find_param(name) == nullptr) {
      throw ParamError("--set: unknown parameter '" + name +
                       "' (known: " + param_names() + ")");
    }
    inputs.push_back({name, o.substr(eq + 1), ValueSource::kOverride, "--set"});
  }
  return inputs;
}

std::vector<ParamInput> ctl_inputs(
    const std::vector<std::pair<std::string, std::string>>& given) {
  std::vector<ParamInput> inputs;
  std::vector<bool> seen(case_fields().size(), false);
  for (const auto& [option, value] : given) {
    const ParamSpec* f = nullptr;
    for (const ParamSpec& row : case_fields()) {
      if (row.ctl_option != nullptr && option == row.ctl_option) f = &row;
    }
    if (f == nullptr) throw ParamError(option + ": not a ctl option");
    seen[row_of(*f)] = true;
    inputs.push_back({f->name, f->ctl_flag ? "1" : value,
                      ValueSource::kOverride, option});
  }
  for (const ParamSpec& f : case_fields()) {
    if (f.ctl_default != nullptr && !seen[row_of(f)]) {
      inputs.insert(inputs.begin(), {f.name, f.ctl_default,
                                     ValueSource::kDefault, f.ctl_option});
    }
  }
  return inputs;
}

CaseParams load_case_params(const std::string& source,
                            const std::vector<ParamInput>& inputs) {
  const std::vector<ParamSpec>& table = case_fields();
  CaseParams c;
  c.source = source;
  c.values.resize(table.size());

  // the values given, in order: a later one wins
  for (const ParamInput& in : inputs) {
    const ParamSpec* spec = find_param(in.name);
    if (spec == nullptr) {
      throw ParamError(in.where + ": unknown parameter '" + in.name +
                       "' (known: " + param_names() + ")");
    }
    store(*spec, in.value, in.source, in.where, &c.values[row_of(*spec)]);
  }

  // required parameters, then the defaults (some depend on the VM)
  for (const ParamSpec& f : table) {
    if (!c.values[row_of(f)].set && f.default_value == nullptr) {
      throw ParamError(source + ": missing <custom> field '" + f.name + "' (" +
                       f.doc + ")");
    }
  }
  const ParamValue& kind = c.values[row_of(row_named("vm_kind"))];
  const bool surface = kind.text == "surface";
  for (const ParamSpec& f : table) {
    ParamValue& v = c.values[row_of(f)];
    if (v.set) continue;
    const char* d = surface && f.surface_default != nullptr ? f.surface_default
                                                            : f.default_value;
    store(f, d, ValueSource::kDefault, source, &v);
  }

  // each value by its row's rule, then the rules between parameters
  for (const ParamSpec& f : table) check_rule(f, c.values[row_of(f)]);
  for (const ParamSpec& f : table) f.bind(&c, c.values[row_of(f)]);

  const auto at = [&c](const char* name) {
    const ParamSpec& f = row_named(name);
    return field_at(f, c.values[row_of(f)]);
  };
  if (c.sim.fault == SensorFaultKind::kJump && c.sim.fault_joint > 3) {
    throw ParamError(at("fault_joint") +
                     " must be a whole number in [1, 3] for a jump (the "
                     "encoders), got " +
                     std::to_string(c.sim.fault_joint));
  }
  const bool jitter_off = c.sim.jitter_min_s == 0.0 && c.sim.jitter_max_s == 0.0;
  if (!jitter_off &&
      !(c.sim.jitter_min_s > 0.0 && c.sim.jitter_max_s >= c.sim.jitter_min_s)) {
    throw ParamError(at("servo_jitter_s") +
                     " must be 0 0 or a range 0 < min <= max");
  }
  if (c.script.dir.norm() < 1e-9) {
    throw ParamError(at("script_dir") + " must not be zero");
  }
  return c;
}

CaseParams case_params_from_fields(const std::vector<CustomField>& fields,
                                   const std::string& source,
                                   const std::vector<std::string>& overrides) {
  for (const CustomField& field : fields) {
    const ParamSpec* f = find_param(field.name);
    if (f == nullptr) {
      throw ParamError(source + ": unknown <custom> field '" + field.name +
                       "' (known: " + param_names() + ")");
    }
    if (f->is_text != field.is_text) {
      throw ParamError(source + ": <custom> field '" + field.name +
                       "' must be a <" + (f->is_text ? "text" : "numeric") +
                       ">, not a <" + (field.is_text ? "text" : "numeric") +
                       ">");
    }
  }
  // in the table's order, as given (a field named twice: MuJoCo keeps one
  // of each name, so the last is taken)
  std::vector<ParamInput> inputs;
  for (const ParamSpec& spec : case_fields()) {
    const CustomField* given = nullptr;
    for (const CustomField& field : fields) {
      if (field.name == spec.name) given = &field;
    }
    if (given != nullptr) {
      inputs.push_back({spec.name, given->value, ValueSource::kScene, source});
    }
  }
  for (ParamInput& set : set_inputs(overrides)) inputs.push_back(std::move(set));
  return load_case_params(source, inputs);
}

ControllerParams case_controller_params(const CaseParams& c) {
  ControllerParams p = controller_params(c);
  if (!c.sim.gimbal_limits) {
    // no limits on q4..q6: ranges that cover every angle for the
    // controller's check, the start pose's IK and the pots' span
    constexpr double kPi = 3.14159265358979323846;
    for (std::size_t i = 3; i < 6; ++i) {
      p.omni.joint_lower_rad[i] = -kPi;
      p.omni.joint_upper_rad[i] = kPi;
    }
  }
  return p;
}

ControllerParams controller_params(const ControllerSettings& s) {
  ControllerParams p;
  p.vm.kind = s.vm_kind;
  p.vm.pivot_mm = s.vm_pivot_mm;
  p.vm.length_mm = s.vm_length_mm;
  p.vm.friction_mu = s.friction_mu;
  p.vm.unilateral = s.unilateral;
  p.gains.k_pos_N_per_mm = s.k_pos_N_per_mm;
  p.gains.k_ornt_Nmm_per_rad =
      thesis_orientation_gain(s.k_ornt_multiple, s.vm_length_mm);
  p.gains.k_vel_Ns_per_mm = s.k_vel_Ns_per_mm;
  p.gains.k_vel_ornt_Nmms_per_rad = s.k_vel_ornt_Nmms_per_rad;
  p.placement_options.weights = s.placement_weights;
  p.projection_weights = s.projection_weights;
  p.length_unit_mm = s.length_unit_mm;
  p.error = s.error;
  p.placement = s.placement;
  p.servo_period_s = s.servo_period_s;
  p.force_limit_N = s.force_limit_N;
  p.omni.motor_torque_limit_Nm = motor_torque_limits_Nm(p.omni, s.torque_limits);
  return p;
}

const ParamSpec* param_of_validate_message(const std::string& message) {
  // ControllerParams' field -> the parameter that sets it
  static const std::pair<const char*, const char*> kFields[] = {
      {"vm.pivot_mm", "vm_pivot_mm"},
      {"vm.length_mm", "vm_length_mm"},
      {"vm.friction_mu", "friction_mu"},
      {"gains.k_pos_N_per_mm", "k_pos_N_per_mm"},
      {"gains.k_ornt_Nmm_per_rad", "k_ornt_multiple"},
      {"gains.k_vel_Ns_per_mm", "k_vel_Ns_per_mm"},
      {"gains.k_vel_ornt_Nmms_per_rad", "k_vel_ornt_Nmms_per_rad"},
      {"placement_options.weights", "placement_weights"},
      {"projection_weights", "projection_weights"},
      {"length_unit_mm", "length_unit_mm"},
      {"servo_period_s", "servo_period_s"},
      {"force_limit_N", "force_limit_N"},
  };
  const std::string prefix = "controller parameter ";
  if (message.rfind(prefix, 0) != 0) return nullptr;
  const std::string field =
      message.substr(prefix.size(), message.find(':') - prefix.size());
  for (const auto& [controller_field, name] : kFields) {
    if (field == controller_field) return find_param(name);
  }
  return nullptr;
}

}  // namespace vmh::sim
