#include "sim/case_config.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "controller/virtual_mechanism.h"
#include "sim/mujoco_util.h"
#include "sim/sim_device.h"

namespace vmh::sim {
namespace {

std::string join_names() {
  std::string all;
  for (const FieldSpec& f : case_fields()) {
    all += (all.empty() ? "" : ", ") + std::string(f.name);
  }
  return all;
}

const FieldSpec* find_field(const std::string& name) {
  for (const FieldSpec& f : case_fields()) {
    if (name == f.name) return &f;
  }
  return nullptr;
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

}  // namespace

const std::vector<FieldSpec>& case_fields() {
  // one line per field: name, text?, size, default, unit, meaning
  static const std::vector<FieldSpec> fields = {
      {"thesis_case", false, 1, "0", "-",
       "which thesis case's claims to check, 1..6 (0: none)"},
      {"vm_kind", true, 1, nullptr, "-",
       "virtual mechanism: circle (eq. 3.25), sphere (eq. 3.29) or surface"},
      {"vm_pivot_mm", false, 3, "0 0 0", "mm",
       "VM pivot, device frame (Appendix D: the origin)"},
      {"vm_length_mm", false, 1, "50", "mm", "VM link length L (Lv = 50)"},
      {"k_pos_N_per_mm", false, 1, "0.5", "N/mm", "K_pos (eq. 3.28)"},
      {"k_ornt_multiple", false, 1, "0", "N/mm",
       "K_ornt as a multiple of the circumference 2 pi L (eq. 3.28)"},
      {"k_vel_Ns_per_mm", false, 1, "0", "N s/mm",
       "K_v on the translational error rate (eq. 3.8)"},
      {"placement_weights", false, 6, "1 1 1 0 0 0", "-",
       "diagonal W of the Gauss-Newton placement (eq. 3.15), W_p by default"},
      {"projection_weights", false, 6, "1 1 1 1 1 1", "-",
       "diagonal W_A of the force projection (Appendix D), identity in the "
       "thesis"},
      {"length_unit_mm", false, 1, "1", "mm",
       "the controller's length unit: 1 = mm (thesis), 1000 = m; the "
       "projection depends on it (docs/control.md)"},
      {"error", true, 1, "thesis", "-",
       "orientation error: thesis (eq. 3.32-3.37) or geometric"},
      {"placement", true, 1, "gauss-newton", "-",
       "VM placement: gauss-newton (eq. 3.15-3.16) or closed"},
      {"servo_period_s", false, 1, "0.001", "s",
       "controller period T; the torque is held over it (ZOH)"},
      {"physics_step_s", false, 1, "0", "s",
       "MuJoCo step h; 0 keeps the scene's <option timestep>; T/h must be "
       "a whole number"},
      {"integrator", true, 1, "scene", "-",
       "MuJoCo integrator: scene (keep the scene's <option integrator>), "
       "euler, implicit or rk4"},
      {"delay_ticks", false, 1, "0", "ticks",
       "servo ticks between a reading and the torque it produces reaching "
       "the motors"},
      {"quantize", false, 1, "1", "-",
       "1: encoder (15000 counts/rev) and potentiometer (11 bit) "
       "quantisation on the readings; 0: exact angles"},
      {"force_limit_N", false, 1, "3.3", "N", "force saturation (Omni peak)"},
      {"duration_s", false, 1, "20", "s", "simulated time of a run"},
      {"script", true, 1, "thesis", "-",
       "hand script: thesis (holds off the path, misaligned on the path, "
       "sweep), hold (stay at the start pose), pivot (start at the VM's "
       "pivot, hold there, then pass through it along script_dir) or spin "
       "(hold the start point, swing the stylus about the VM's normal by "
       "+-script_misalign_rad)"},
      {"script_dir", false, 3, "-0.35 0.65 0.65", "-",
       "device-frame direction from the pivot to the start pose; also the "
       "stylus axis there"},
      {"script_axis", false, 3, "0 0 0", "-",
       "device-frame stylus axis at the start pose; 0 0 0: along "
       "script_dir"},
      {"script_off_mm", false, 1, "60", "mm",
       "how far off the path the hand target is held"},
      {"script_misalign_rad", false, 1, "0.5", "rad",
       "stylus misalignment on the path"},
      {"script_sweep_mm", false, 1, "40", "mm",
       "amplitude across the path during the sweep"},
      {"script_sweep_rad", false, 1, "0.5", "rad",
       "amplitude along the path (about the pivot) during the sweep"},
      {"servo_jitter_s", false, 2, "0 0", "s",
       "shortest and longest servo period, whole multiples of the physics "
       "step; each tick's is drawn uniformly among them, and the controller "
       "is still told servo_period_s. 0 0: every period is servo_period_s. The extreme "
       "cases use 0.4e-3 2.8e-3: 2.8 ms is a USB Touch's worst case, the "
       "range far wider than its measured spread (docs/sources.md 6)"},
      {"jitter_seed", false, 1, "1", "-",
       "seed of the servo-period draws (whole number)"},
      {"fault", true, 1, "none", "-",
       "injected sensor fault: none, nan (the joint reads NaN), jump (an "
       "encoder reads 1000 counts high from then on) or stuck (the joint "
       "keeps its reading)"},
      {"fault_joint", false, 1, "1", "-",
       "device joint of the fault, 1..6 (t1..t6); jump: 1..3, the encoders"},
      {"fault_at_s", false, 1, "1", "s", "when the fault begins"},
      {"sensor_guard", false, 1, "1", "-",
       "1: the device layer refuses non-finite readings and latches on an "
       "encoder step faster than guard_max_speed_rad_s (sensor_fault, zero "
       "torque); 0: readings pass unchecked"},
      {"guard_max_speed_rad_s", false, 1, "50", "rad/s",
       "fastest plausible actuated-joint speed (estimate); the largest "
       "accepted step is this times the longest servo period"},
      {"gimbal_limits", false, 1, "1", "-",
       "1: the gimbal joints q4..q6 stop at their ranges; 0: no limits in "
       "the model or the controller, so that the wrist can reach its "
       "singularity q5 = +-pi/2"},
      {"hand_mass_kg", false, 1, "0.554", "kg",
       "hand mass at the grip (van Beek et al. 2015)"},
      {"hand_inertia_kgm2", false, 3, "2e-4 2e-4 2e-4", "kg m^2",
       "hand rotational inertia about the grip, stylus axes"},
      {"hand_k_pos_N_per_m", false, 1, "135", "N/m",
       "hand translational stiffness (van Beek et al. 2015)"},
      {"hand_b_pos_Ns_per_m", false, 1, "6.45", "N s/m",
       "hand translational damping (van Beek et al. 2015)"},
      {"hand_k_rot_Nm_per_rad", false, 1, "0.5", "N m/rad",
       "hand rotational stiffness (estimate, models/hand/README.md)"},
      {"hand_b_rot_Nms_per_rad", false, 1, "0.02", "N m s/rad",
       "hand rotational damping (estimate, models/hand/README.md)"},
  };
  return fields;
}

const char* value_source_name(ValueSource s) {
  switch (s) {
    case ValueSource::kDefault: return "default";
    case ValueSource::kScene: return "scene";
    case ValueSource::kOverride: return "set";
  }
  return "unknown";
}

CaseConfig CaseConfig::from_model(const mjModel* m, const std::string& source,
                                  const std::vector<std::string>& overrides) {
  CaseConfig c;
  c.scene_path_ = source;

  // every custom field of the scene must be one we know, under the tag of
  // its kind: a number written as <text> (or a word as <numeric>) would
  // otherwise be skipped and its default used without a word
  auto check_tag = [&](const char* name, bool as_text) {
    const FieldSpec* f = find_field(name);
    if (f == nullptr) {
      throw SimError(source + ": unknown <custom> field '" + name +
                     "' (known: " + join_names() + ")");
    }
    if (f->is_text != as_text) {
      throw SimError(source + ": <custom> field '" + name + "' must be a <" +
                     (f->is_text ? "text" : "numeric") + ">, not a <" +
                     (as_text ? "text" : "numeric") + ">");
    }
  };
  for (int i = 0; i < m->nnumeric; ++i) {
    check_tag(m->names + m->name_numericadr[i], false);
  }
  for (int i = 0; i < m->ntext; ++i) {
    check_tag(m->names + m->name_textadr[i], true);
  }

  auto store = [&c](const FieldSpec& f, const std::string& value,
                    ValueSource from, const std::string& where) {
    if (f.is_text) {
      c.texts_[f.name] = value;
    } else {
      std::vector<double> v;
      if (!parse_numbers(value, &v)) {
        throw SimError(where + ": field '" + f.name + "' expects numbers, got '" +
                       value + "'");
      }
      if (static_cast<int>(v.size()) != f.size) {
        throw SimError(where + ": field '" + f.name + "' expects " +
                       std::to_string(f.size) + " value(s), got " +
                       std::to_string(v.size()));
      }
      for (double x : v) {
        if (!std::isfinite(x)) {
          throw SimError(where + ": field '" + f.name + "' is not finite");
        }
      }
      c.numbers_[f.name] = v;
    }
    c.sources_[f.name] = from;
  };

  for (const FieldSpec& f : case_fields()) {
    if (f.is_text) {
      const char* t = custom_text(m, f.name);
      if (t != nullptr) {
        store(f, t, ValueSource::kScene, source);
        continue;
      }
    } else {
      const std::vector<double> v = custom_numeric(m, f.name);
      if (!v.empty()) {
        std::ostringstream s;
        s.precision(17);
        for (double x : v) s << x << ' ';
        store(f, s.str(), ValueSource::kScene, source);
        continue;
      }
    }
    if (f.default_value != nullptr) {
      store(f, f.default_value, ValueSource::kDefault, source);
    }
  }

  for (const std::string& o : overrides) {
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw SimError("--set '" + o + "': expected name=value");
    }
    const std::string name = o.substr(0, eq);
    const FieldSpec* f = find_field(name);
    if (f == nullptr) {
      throw SimError("--set: unknown parameter '" + name +
                     "' (known: " + join_names() + ")");
    }
    store(*f, o.substr(eq + 1), ValueSource::kOverride, "--set " + name);
  }

  // required fields
  for (const FieldSpec& f : case_fields()) {
    if (c.sources_.count(f.name) == 0) {
      throw SimError(source + ": missing <custom> field '" + f.name + "' (" +
                     f.doc + ")");
    }
  }

  // value checks, each naming its field
  auto where = [&c](const char* name) {
    return (c.sources_.at(name) == ValueSource::kOverride
                ? std::string("--set")
                : c.scene_path_) +
           ": field '" + name + "'";
  };
  VmKind kind;
  if (!parse_vm_kind(c.text("vm_kind").c_str(), &kind)) {
    throw SimError(where("vm_kind") + " must be circle, sphere or surface, got '" +
                   c.text("vm_kind") + "'");
  }
  ErrorFormulation ef;
  if (!parse_error_formulation(c.text("error").c_str(), &ef)) {
    throw SimError(where("error") + " must be thesis or geometric, got '" +
                   c.text("error") + "'");
  }
  PlacementMethod pm;
  if (!parse_placement_method(c.text("placement").c_str(), &pm)) {
    throw SimError(where("placement") +
                   " must be gauss-newton or closed, got '" +
                   c.text("placement") + "'");
  }
  const std::string& script = c.text("script");
  if (script != "thesis" && script != "hold" && script != "pivot" &&
      script != "spin") {
    throw SimError(where("script") +
                   " must be thesis, hold, pivot or spin, got '" + script +
                   "'");
  }
  const std::string& fault = c.text("fault");
  if (fault != "none" && fault != "nan" && fault != "jump" &&
      fault != "stuck") {
    throw SimError(where("fault") + " must be none, nan, jump or stuck, got '" +
                   fault + "'");
  }
  const std::string& integrator = c.text("integrator");
  if (integrator != "scene" && integrator != "euler" &&
      integrator != "implicit" && integrator != "rk4") {
    throw SimError(where("integrator") +
                   " must be scene, euler, implicit or rk4, got '" +
                   integrator + "'");
  }
  auto positive = [&](const char* name) {
    if (!(c.number(name) > 0.0)) {
      throw SimError(where(name) + " must be > 0, got " +
                     std::to_string(c.number(name)));
    }
  };
  auto non_negative = [&](const char* name) {
    if (!(c.number(name) >= 0.0)) {
      throw SimError(where(name) + " must be >= 0, got " +
                     std::to_string(c.number(name)));
    }
  };
  auto whole = [&](const char* name, double lo, double hi) {
    const double v = c.number(name);
    if (v != std::floor(v) || v < lo || v > hi) {
      throw SimError(where(name) + " must be a whole number in [" +
                     std::to_string(static_cast<int>(lo)) + ", " +
                     std::to_string(static_cast<int>(hi)) + "], got " +
                     std::to_string(v));
    }
  };
  for (const char* n : {"vm_length_mm", "servo_period_s", "force_limit_N",
                        "length_unit_mm",
                        "duration_s", "hand_mass_kg"}) {
    positive(n);
  }
  for (const char* n :
       {"k_pos_N_per_mm", "k_ornt_multiple", "k_vel_Ns_per_mm", "physics_step_s",
        "script_off_mm", "script_sweep_mm", "hand_k_pos_N_per_m",
        "hand_b_pos_Ns_per_m", "hand_k_rot_Nm_per_rad",
        "hand_b_rot_Nms_per_rad"}) {
    non_negative(n);
  }
  whole("thesis_case", 0, 6);
  whole("delay_ticks", 0, kMaxDelayTicks);
  whole("quantize", 0, 1);
  whole("sensor_guard", 0, 1);
  whole("gimbal_limits", 0, 1);
  whole("fault_joint", 1, fault == "jump" ? 3 : 6);
  whole("jitter_seed", 0, 2147483647.0);
  positive("guard_max_speed_rad_s");
  non_negative("fault_at_s");
  {
    const std::vector<double> j = c.numbers("servo_jitter_s");
    const bool off = j[0] == 0.0 && j[1] == 0.0;
    if (!off && !(j[0] > 0.0 && j[1] >= j[0])) {
      throw SimError(where("servo_jitter_s") +
                     " must be 0 0 or a range 0 < min <= max");
    }
  }
  for (const char* n : {"placement_weights", "projection_weights"}) {
    for (double w : c.numbers(n)) {
      if (w < 0.0) throw SimError(where(n) + " must be >= 0");
    }
  }
  for (double i : c.numbers("hand_inertia_kgm2")) {
    if (!(i > 0.0)) throw SimError(where("hand_inertia_kgm2") + " must be > 0");
  }
  if (c.vec3("script_dir").norm() < 1e-9) {
    throw SimError(where("script_dir") + " must not be zero");
  }
  return c;
}

double CaseConfig::number(const std::string& name) const {
  return numbers_.at(name).at(0);
}

std::vector<double> CaseConfig::numbers(const std::string& name) const {
  return numbers_.at(name);
}

Vec3 CaseConfig::vec3(const std::string& name) const {
  const std::vector<double>& v = numbers_.at(name);
  return Vec3(v.at(0), v.at(1), v.at(2));
}

const std::string& CaseConfig::text(const std::string& name) const {
  return texts_.at(name);
}

ValueSource CaseConfig::source_of(const std::string& name) const {
  return sources_.at(name);
}

ControllerParams controller_params(const CaseConfig& c) {
  ControllerParams p;
  parse_vm_kind(c.text("vm_kind").c_str(), &p.vm.kind);
  p.vm.pivot_mm = c.vec3("vm_pivot_mm");
  p.vm.length_mm = c.number("vm_length_mm");
  p.gains.k_pos_N_per_mm = c.number("k_pos_N_per_mm");
  p.gains.k_ornt_Nmm_per_rad =
      thesis_orientation_gain(c.number("k_ornt_multiple"), p.vm.length_mm);
  p.gains.k_vel_Ns_per_mm = c.number("k_vel_Ns_per_mm");
  const std::vector<double> w = c.numbers("placement_weights");
  const std::vector<double> wa = c.numbers("projection_weights");
  for (int i = 0; i < 6; ++i) {
    p.placement_options.weights[i] = w[i];
    p.projection_weights[i] = wa[i];
  }
  p.length_unit_mm = c.number("length_unit_mm");
  parse_error_formulation(c.text("error").c_str(), &p.error);
  parse_placement_method(c.text("placement").c_str(), &p.placement);
  p.servo_period_s = c.number("servo_period_s");
  p.force_limit_N = c.number("force_limit_N");
  return p;
}

}  // namespace vmh::sim
