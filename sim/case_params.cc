#include "sim/case_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "controller/virtual_mechanism.h"
#include "sim/sim_device.h"  // kMaxDelayTicks

namespace vmh::sim {
namespace {

// ---- reading a value's items ---------------------------------------------

double item(const ParamValue& v) { return v.numbers.at(0); }
Vec3 vec3(const ParamValue& v) {
  return Vec3(v.numbers.at(0), v.numbers.at(1), v.numbers.at(2));
}
Vec6 vec6(const ParamValue& v) {
  Vec6 out;
  for (int i = 0; i < 6; ++i) out[i] = v.numbers.at(static_cast<std::size_t>(i));
  return out;
}
bool flag(const ParamValue& v) { return item(v) != 0.0; }
int whole(const ParamValue& v) { return static_cast<int>(item(v)); }

// the position of `text` in a ", "-separated list of words; -1 if absent
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

// ---- building the table's rows -------------------------------------------

using Bind = void (*)(CaseParams*, const ParamValue&);

// a row with chainable setters for its optional columns
struct Row : ParamSpec {
  Row& positive() { rule = ParamRule::kPositive; return *this; }
  Row& non_negative() { rule = ParamRule::kNonNegative; return *this; }
  Row& whole_in(double l, double h) {
    rule = ParamRule::kWhole;
    lo = l;
    hi = h;
    return *this;
  }
  Row& flag01() { return whole_in(0, 1); }
  Row& infinite_ok() { allow_inf = true; return *this; }
  Row& note(const char* n) { range_note = n; return *this; }
  Row& on_surface(const char* d) { surface_default = d; return *this; }
  Row& ctl(const char* option) { ctl_option = option; return *this; }
  Row& ctl_default_is(const char* d) { ctl_default = d; return *this; }
  Row& ctl_as_flag() { ctl_flag = true; return *this; }
};

Row numeric(const char* group, const char* name, int size, const char* def,
            const char* unit, const char* doc, Bind bind) {
  Row r{};
  r.name = name;
  r.is_text = false;
  r.size = size;
  r.default_value = def;
  r.unit = unit;
  r.doc = doc;
  r.group = group;
  r.bind = bind;
  return r;
}

Row text(const char* group, const char* name, const char* def,
         const char* words, const char* doc, Bind bind) {
  Row r = numeric(group, name, 1, def, "-", doc, bind);
  r.is_text = true;
  r.words = words;
  return r;
}

std::string format_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

const std::vector<ParamSpec>& case_fields() {
  static const std::vector<ParamSpec> fields = {
      // ---- the case ----
      numeric("case", "thesis_case", 1, "0", "-",
              "which thesis case's claims to check, 1..6 (0: none)",
              [](CaseParams* p, const ParamValue& v) {
                p->thesis_case = whole(v);
              })
          .whole_in(0, 6),

      // ---- the controller (scenes and `ctl` alike) ----
      text("controller", "vm_kind", nullptr, "circle, sphere, surface",
           "virtual mechanism: circle (eq. 3.25), sphere (eq. 3.29) or "
           "surface",
           [](CaseParams* p, const ParamValue& v) {
             parse_vm_kind(v.text.c_str(), &p->controller.vm_kind);
           })
          .ctl("--vm")
          .ctl_default_is("circle"),
      numeric("controller", "vm_pivot_mm", 3, "0 0 0", "mm",
              "VM pivot (circle, sphere) or a point of the plane (surface), "
              "device frame (Appendix D: the origin)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.vm_pivot_mm = vec3(v);
              })
          .ctl("--pivot-mm"),
      numeric("controller", "vm_length_mm", 1, "50", "mm",
              "VM link length L (Lv = 50)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.vm_length_mm = item(v);
              })
          .positive()
          .ctl("--length-mm"),
      numeric("controller", "friction_mu", 1, "0", "-",
              "surface only: Coulomb coefficient of the contact point; 0 "
              "slides freely (the 5-DOF VM of section 3.1), > 0 sticks until "
              "|f_t| > mu f_n, inf never slides",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.friction_mu = item(v);
              })
          .non_negative()
          .infinite_ok()
          .ctl("--mu"),
      numeric("controller", "unilateral", 1, "0", "-",
              "surface only: 1: the plane only pushes, the probe may lift "
              "off; 0: the probe is held on the plane",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.unilateral = flag(v);
              })
          .flag01()
          .ctl("--unilateral")
          .ctl_as_flag(),
      numeric("controller", "k_pos_N_per_mm", 1, "0.5", "N/mm",
              "K_pos, the stiffness of the position rows (eq. 3.28)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.k_pos_N_per_mm = item(v);
              })
          .non_negative()
          .ctl("--kpos"),
      numeric("controller", "k_ornt_multiple", 1, "0", "N/mm",
              "K_ornt, the stiffness of the orientation rows, as a multiple "
              "of the circumference: K_ornt = multiple x 2 pi L N mm/rad "
              "(eq. 3.28)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.k_ornt_multiple = item(v);
              })
          .non_negative()
          .ctl("--kornt"),
      numeric("controller", "k_vel_Ns_per_mm", 1, "0", "N s/mm",
              "K_v on the position rows' error rate (eq. 3.8); the "
              "orientation rows have their own, k_vel_ornt_Nmms_per_rad",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.k_vel_Ns_per_mm = item(v);
              })
          .non_negative()
          .ctl("--kv"),
      numeric("controller", "k_vel_ornt_Nmms_per_rad", 1, "0", "N mm s/rad",
              "K_v on the orientation rows' error rate (eq. 3.8); "
              "k_vel_Ns_per_mm x 2 pi L gives the damping analogue of eq. "
              "3.28",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.k_vel_ornt_Nmms_per_rad = item(v);
              })
          .non_negative()
          .ctl("--kv-ornt"),
      numeric("controller", "placement_weights", 6, "1 1 1 0 0 0", "-",
              "diagonal W of the Gauss-Newton placement (eq. 3.15): x, y, z, "
              "theta_x, theta_y, theta_z; W_p by default, all ones for the "
              "surface (its orientation rows place it); not all zero",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.placement_weights = vec6(v);
              })
          .non_negative()
          .on_surface("1 1 1 1 1 1")
          .ctl("--weights"),
      numeric("controller", "projection_weights", 6, "1 1 1 1 1 1", "-",
              "diagonal W_A of the force projection (Appendix D), identity in "
              "the thesis",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.projection_weights = vec6(v);
              })
          .positive()
          .ctl("--projection-weights"),
      numeric("controller", "length_unit_mm", 1, "1", "mm",
              "the controller's length unit: 1 = mm (thesis), 1000 = m; the "
              "projection depends on it (docs/control.md)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.length_unit_mm = item(v);
              })
          .positive()
          .ctl("--length-unit-mm"),
      text("controller", "error", "thesis", "thesis, geometric",
           "orientation error: thesis (eq. 3.32-3.37) or geometric",
           [](CaseParams* p, const ParamValue& v) {
             parse_error_formulation(v.text.c_str(), &p->controller.error);
           })
          .ctl("--error"),
      text("controller", "placement", "gauss-newton", "gauss-newton, closed",
           "VM placement: gauss-newton (eq. 3.15-3.16) or closed",
           [](CaseParams* p, const ParamValue& v) {
             parse_placement_method(v.text.c_str(), &p->controller.placement);
           })
          .ctl("--placement"),
      numeric("controller", "servo_period_s", 1, "0.001", "s",
              "controller period T: the e_dot difference uses it, the torque "
              "is held over it (ZOH)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.servo_period_s = item(v);
              })
          .positive()
          .ctl("--servo-period-s"),
      numeric("controller", "force_limit_N", 1, "3.3", "N",
              "force saturation (Omni peak)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.force_limit_N = item(v);
              })
          .positive()
          .ctl("--force-limit-N"),

      // ---- the simulator ----
      numeric("sim", "physics_step_s", 1, "0", "s",
              "MuJoCo step h; 0 keeps the scene's `<option timestep>`; T/h must "
              "be a whole number",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.physics_step_s = item(v);
              })
          .non_negative(),
      text("sim", "integrator", "scene", "scene, euler, implicit, rk4",
           "MuJoCo integrator: scene (keep the scene's `<option integrator>`), "
           "euler, implicit or rk4",
           [](CaseParams* p, const ParamValue& v) {
             p->sim.integrator = static_cast<IntegratorSetting>(
                 word_index("scene, euler, implicit, rk4", v.text));
           }),
      numeric("sim", "delay_ticks", 1, "0", "ticks",
              "servo ticks between a reading and the torque it produces "
              "reaching the motors",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.delay_ticks = whole(v);
              })
          .whole_in(0, kMaxDelayTicks),
      numeric("sim", "quantize", 1, "1", "-",
              "1: encoder (15000 counts/rev) and potentiometer (11 bit) "
              "quantisation on the readings; 0: exact angles",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.quantize = flag(v);
              })
          .flag01(),
      numeric("sim", "duration_s", 1, "20", "s", "simulated time of a run",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.duration_s = item(v);
              })
          .positive(),

      // ---- the hand script ----
      text("script", "script", "thesis", "thesis, hold, pivot, spin",
           "hand script: thesis (holds off the path, misaligned on the path, "
           "sweep), hold (stay at the start pose), pivot (start at the VM's "
           "pivot, hold there, then pass through it along script_dir) or "
           "spin (hold the start point, swing the stylus about the VM's "
           "normal by +-script_misalign_rad)",
           [](CaseParams* p, const ParamValue& v) {
             p->script.name = v.text;
             p->script.kind = static_cast<ScriptKind>(
                 word_index("thesis, hold, pivot, spin", v.text));
           }),
      numeric("script", "script_dir", 3, "-0.35 0.65 0.65", "-",
              "device-frame direction from the pivot to the start pose; also "
              "the stylus axis there",
              [](CaseParams* p, const ParamValue& v) {
                p->script.dir = vec3(v);
              })
          .note("not 0 0 0"),
      numeric("script", "script_axis", 3, "0 0 0", "-",
              "device-frame stylus axis at the start pose; 0 0 0: along "
              "script_dir",
              [](CaseParams* p, const ParamValue& v) {
                p->script.axis = vec3(v);
              }),
      numeric("script", "script_off_mm", 1, "60", "mm",
              "how far off the path the hand target is held",
              [](CaseParams* p, const ParamValue& v) {
                p->script.off_mm = item(v);
              })
          .non_negative(),
      numeric("script", "script_misalign_rad", 1, "0.5", "rad",
              "stylus misalignment on the path",
              [](CaseParams* p, const ParamValue& v) {
                p->script.misalign_rad = item(v);
              }),
      numeric("script", "script_sweep_mm", 1, "40", "mm",
              "amplitude across the path during the sweep",
              [](CaseParams* p, const ParamValue& v) {
                p->script.sweep_mm = item(v);
              })
          .non_negative(),
      numeric("script", "script_sweep_rad", 1, "0.5", "rad",
              "amplitude along the path (about the pivot) during the sweep",
              [](CaseParams* p, const ParamValue& v) {
                p->script.sweep_rad = item(v);
              }),

      // ---- servo jitter, faults, the guard, the gimbal ----
      numeric("sim", "servo_jitter_s", 2, "0 0", "s",
              "shortest and longest servo period, whole multiples of the "
              "physics step; each tick's is drawn uniformly among them, and "
              "the controller is still told servo_period_s. 0 0: every period "
              "is servo_period_s. The extreme cases use 0.4e-3 2.8e-3: 2.8 ms "
              "is a USB Touch's worst case, the range far wider than its "
              "measured spread (docs/sources.md §6)",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.jitter_min_s = v.numbers.at(0);
                p->sim.jitter_max_s = v.numbers.at(1);
              })
          .note("0 0, or 0 < min <= max"),
      numeric("sim", "jitter_seed", 1, "1", "-",
              "seed of the servo-period draws (whole number)",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.jitter_seed = static_cast<std::uint64_t>(item(v));
              })
          .whole_in(0, 2147483647.0),
      text("sim", "fault", "none", "none, nan, jump, stuck",
           "injected sensor fault: none, nan (the joint reads NaN), jump (an "
           "encoder reads 1000 counts high from then on) or stuck (the joint "
           "keeps its reading)",
           [](CaseParams* p, const ParamValue& v) {
             parse_sensor_fault_kind(v.text, &p->sim.fault);
           }),
      numeric("sim", "fault_joint", 1, "1", "-",
              "device joint of the fault, 1..6 (t1..t6); jump: 1..3, the "
              "encoders",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.fault_joint = whole(v);
              })
          .whole_in(1, 6)
          .note("fault jump: 1 .. 3"),
      numeric("sim", "fault_at_s", 1, "1", "s", "when the fault begins",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.fault_at_s = item(v);
              })
          .non_negative(),
      numeric("sim", "sensor_guard", 1, "1", "-",
              "1: the device layer refuses non-finite readings and latches on "
              "an encoder step faster than guard_max_speed_rad_s "
              "(sensor_fault, zero torque); 0: readings pass unchecked",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.sensor_guard = flag(v);
              })
          .flag01(),
      numeric("sim", "guard_max_speed_rad_s", 1, "50", "rad/s",
              "fastest plausible actuated-joint speed (estimate); the largest "
              "accepted step is this times the longest servo period",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.guard_max_speed_rad_s = item(v);
              })
          .positive(),
      numeric("sim", "gimbal_limits", 1, "1", "-",
              "1: the gimbal joints q4..q6 stop at their ranges; 0: no limits "
              "in the model or the controller, so that the wrist can reach "
              "its singularity q5 = +-pi/2",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.gimbal_limits = flag(v);
              })
          .flag01(),

      // ---- the hand ----
      numeric("hand", "hand_mass_kg", 1, "0.554", "kg",
              "hand mass at the grip (van Beek et al. 2015)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.mass_kg = item(v);
              })
          .positive(),
      numeric("hand", "hand_inertia_kgm2", 3, "2e-4 2e-4 2e-4", "kg m^2",
              "hand rotational inertia about the grip, stylus axes",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.inertia_kgm2 = vec3(v);
              })
          .positive(),
      numeric("hand", "hand_k_pos_N_per_m", 1, "135", "N/m",
              "hand translational stiffness (van Beek et al. 2015)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.k_pos_N_per_m = item(v);
              })
          .non_negative(),
      numeric("hand", "hand_b_pos_Ns_per_m", 1, "6.45", "N s/m",
              "hand translational damping (van Beek et al. 2015)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.b_pos_Ns_per_m = item(v);
              })
          .non_negative(),
      numeric("hand", "hand_k_rot_Nm_per_rad", 1, "0.5", "N m/rad",
              "hand rotational stiffness (estimate, models/hand/README.md)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.k_rot_Nm_per_rad = item(v);
              })
          .non_negative(),
      numeric("hand", "hand_b_rot_Nms_per_rad", 1, "0.02", "N m s/rad",
              "hand rotational damping (estimate, models/hand/README.md)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.b_rot_Nms_per_rad = item(v);
              })
          .non_negative(),
  };
  return fields;
}

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
  for (double x : v.numbers) {
    const std::string got = ", got " + format_number(x);
    switch (spec.rule) {
      case ParamRule::kAny:
        break;
      case ParamRule::kPositive:
        if (!(x > 0.0)) throw ParamError(field_at(spec, v) + " must be > 0" + got);
        break;
      case ParamRule::kNonNegative:
        if (!(x >= 0.0)) {
          throw ParamError(field_at(spec, v) + " must be >= 0" + got);
        }
        break;
      case ParamRule::kWhole:
        if (x != std::floor(x) || x < spec.lo || x > spec.hi) {
          throw ParamError(field_at(spec, v) + " must be " +
                           spec.range_text() + got);
        }
        break;
    }
  }
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

std::string ParamSpec::range_text() const {
  std::string r;
  if (is_text) {
    r = words;
  } else {
    switch (rule) {
      case ParamRule::kAny: r = "any"; break;
      case ParamRule::kPositive: r = "> 0"; break;
      case ParamRule::kNonNegative: r = allow_inf ? ">= 0, or inf" : ">= 0"; break;
      case ParamRule::kWhole:
        r = lo == 0 && hi == 1 ? std::string("0 or 1")
                               : "a whole number in [" + format_number(lo) +
                                     ", " + format_number(hi) + "]";
        break;
    }
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

namespace {

std::string cell(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '|') out += '\\';
    out += ch;
  }
  return out;
}

std::string type_text(const ParamSpec& f) {
  if (f.is_text) return "text";
  if (f.rule == ParamRule::kWhole && f.lo == 0 && f.hi == 1) return "0/1";
  if (f.size == 1) return "number";
  return std::to_string(f.size) + " numbers";
}

}  // namespace

std::string parameters_markdown() {
  std::ostringstream md;
  md << "# Case parameters\n"
        "\n"
        "<!-- Generated by `vmhaptics params`; do not edit by hand. The table "
        "is sim/case_params.cc's case_fields(), and tests/cli/ctl_test.cc "
        "checks that this file is what the program prints. -->\n"
        "\n"
        "Every parameter of a case is defined once, in one table, from which "
        "the scene loader, its checks, `vmhaptics ctl`'s options and this "
        "page are made. A parameter is set, from the weakest to the "
        "strongest:\n"
        "\n"
        "1. by its default (below);\n"
        "2. in the scene, as a `<custom>` field of its name: "
        "`<numeric name=\"k_pos_N_per_mm\" data=\"0.6\"/>` (numbers, "
        "space-separated) or `<text name=\"vm_kind\" data=\"circle\"/>` "
        "(text);\n"
        "3. by `vmhaptics run --set name=value` (vectors comma- or "
        "space-separated; a later `--set` wins).\n"
        "\n"
        "`vmhaptics ctl` has no scene: its options (column `ctl`) set the "
        "controller's parameters, with the same names, meanings, defaults and "
        "checks, and both routes build the controller's parameters with the "
        "same function (controller_params in sim/case_params.h).\n"
        "\n"
        "A field the table does not know, a number written as `<text>` (or a "
        "word as `<numeric>`), the wrong number of values, a value that is "
        "not finite (`friction_mu` may be `inf`) or out of range is refused "
        "when the case is loaded, naming the file (or `--set`, or the ctl "
        "option) and the field. summary.json lists every parameter with its "
        "value, unit and source (`default`, `scene` or `set`).\n"
        "\n"
        "Frames: positions and directions are in the device frame (Omni "
        "origin, mm) unless named. Velocity damping: `k_vel_Ns_per_mm` acts "
        "on the position rows only and `k_vel_ornt_Nmms_per_rad` on the "
        "orientation rows; `ctl --kv` is the first and `ctl --kv-ornt` the "
        "second (before, `ctl --kv` also set the orientation rows to kv x 2 "
        "pi L, which a scene could not).\n";
  const std::pair<const char*, const char*> groups[] = {
      {"case", "The case"},
      {"controller", "The controller (scenes and `ctl`)"},
      {"sim", "The simulator"},
      {"script", "The hand script"},
      {"hand", "The hand"},
  };
  for (const auto& [group, title] : groups) {
    md << "\n## " << title << "\n\n"
       << "| Parameter (`<custom>`, `--set`) | ctl | Type | Unit | Default | "
          "Range | Meaning |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (const ParamSpec& f : case_fields()) {
      if (std::string(f.group) != group) continue;
      std::string ctl = "-";
      if (f.ctl_option != nullptr) {
        ctl = std::string("`") + f.ctl_option + "`";
      }
      md << "| `" << f.name << "` | " << ctl << " | " << type_text(f) << " | "
         << cell(f.unit) << " | " << cell(f.default_text()) << " | "
         << cell(f.range_text()) << " | " << cell(f.doc) << " |\n";
    }
  }
  return md.str();
}

}  // namespace vmh::sim
