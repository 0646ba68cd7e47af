// The table of case parameters (case_fields()): every parameter a scene may
// set, once, with its binding to the typed CaseParams member. The loader that
// reads values against it is case_params.cc.
#include "sim/cases/case_params.h"

#include <cmath>
#include <string>

#include "controller/virtual_mechanism.h"
#include "controller/vm_registry.h"
#include "sim/cases/case_params_detail.h"

namespace vmh::sim {
namespace {

using detail::word_index;

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
  Row& in_range(double l, double h) {
    rule = ParamRule::kInRange;
    lo = l;
    hi = h;
    return *this;
  }
  // with positive() or non_negative(): also <= h
  Row& at_most(double h) {
    has_max = true;
    hi = h;
    return *this;
  }
  Row& infinite_ok() { allow_inf = true; return *this; }
  Row& note(const char* n) { range_note = n; return *this; }
  Row& source(const char* r) { reference = r; return *this; }
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

}  // namespace

namespace {

// the registered mechanisms' names ("circle, sphere, surface, line") and
// one line on each, for vm_kind (controller/vm_registry.h)
const std::string& vm_kind_words() {
  static const std::string words = vm_kind_names();
  return words;
}

const std::string& vm_kind_doc() {
  static const std::string doc = [] {
    std::string d = "virtual mechanism (controller/vm_registry.h):";
    const auto& all = vm_registry();
    for (std::size_t i = 0; i < all.size(); ++i) {
      d += std::string(i == 0 ? " " : "; ") + all[i].name + ", " +
           all[i].summary;
    }
    return d;
  }();
  return doc;
}

}  // namespace

const std::vector<ParamSpec>& case_fields() {
  static const std::vector<ParamSpec> fields = {
      // ---- the case ----
      numeric("case", "thesis_case", 1, "0", "-",
              "which case's claims to check: 1..6 the thesis's, 7 the line "
              "slider's (this project's, the circle's limit; "
              "docs/testbed.md); 0: none",
              [](CaseParams* p, const ParamValue& v) {
                p->thesis_case = whole(v);
              })
          .whole_in(0, 7),

      // ---- the controller (scenes and `ctl` alike) ----
      text("controller", "vm_kind", nullptr, vm_kind_words().c_str(),
           vm_kind_doc().c_str(),
           [](CaseParams* p, const ParamValue& v) {
             parse_vm_kind(v.text.c_str(), &p->controller.vm_kind);
           })
          .ctl("--vm")
          .ctl_default_is("circle"),
      numeric("controller", "vm_pivot_mm", 3, "0 0 0", "mm",
              "VM pivot (circle, sphere), a point of the plane (surface) or "
              "of the line (line), device frame (Appendix D: the origin)",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.vm_pivot_mm = vec3(v);
              })
          .ctl("--pivot-mm"),
      numeric("controller", "vm_length_mm", 1, "50", "mm",
              "VM link length L (Lv = 50); the line slider does not use it in "
              "its law: its drawn link and the scripts' scale",
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
      numeric("controller", "k_ornt_multiple", 1, "0", "N/rad",
              "K_ornt, the stiffness of the orientation rows, as a multiple "
              "of the circumference: K_ornt = multiple x 2 pi L N mm/rad "
              "(eq. 3.28), so the multiple is in N/rad",
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
              "is held over it (ZOH). 1e-5 s (100 kHz) to 1 s: the Omni's "
              "servo loop runs at 1 kHz",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.servo_period_s = item(v);
              })
          .in_range(1e-5, 1.0)
          .ctl("--servo-period-s"),
      numeric("controller", "force_limit_N", 1, "3.3", "N",
              "force saturation; at most the Omni's rated peak, which a "
              "larger limit would only hand on to the motors' clamps",
              [](CaseParams* p, const ParamValue& v) {
                p->controller.force_limit_N = item(v);
              })
          // from the controller's smallest (kMinForceLimit_N)
          .in_range(kMinForceLimit_N, 3.3)
          .source("the PHANTOM Omni's rated peak force at the nominal pose "
                  "(docs/sources.md, 7)")
          .ctl("--force-limit-N"),
      text("controller", "torque_limits", "openhaptics_samples",
           "openhaptics_samples, rated",
           "motor torque limits t1..t3: openhaptics_samples (0.2, 0.35, 0.2 "
           "N m) or rated (the rated 3.3 N in any direction at the nominal "
           "pose, 0.44 N m each; the scene's motor ranges follow)",
           [](CaseParams* p, const ParamValue& v) {
             p->controller.torque_limits = parse_torque_limits(v.text);
           })
          .ctl("--torque-limits")
          .source("the OpenHaptics samples' clamps; rated: the 3.3 N peak at the nominal pose (docs/safety.md; docs/sources.md, 7)"),

      // ---- the simulator ----
      numeric("sim", "physics_step_s", 1, "0", "s",
              "MuJoCo step h; 0 keeps the scene's `<option timestep>` (which "
              "must then be finite and > 0); T/h must be a whole number",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.physics_step_s = item(v);
              })
          .non_negative()
          .at_most(1.0)
          .note("servo_period_s / h a whole number in [1, 1000000]"),
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
      numeric("sim", "duration_s", 1, "20", "s",
              "simulated time of a run, at least one servo period; at most "
              "an hour. `run` writes trace.csv as it goes (about 0.55 kB a "
              "tick, 2 GB for 3600 s at 1 kHz; --out's disk is checked for "
              "room first) and keeps at most 60,000 ticks in memory for the "
              "claims and figures (every k-th beyond: summary.json's "
              "measured_every_ticks)",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.duration_s = item(v);
              })
          .positive()
          .at_most(3600.0),

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
      numeric("script", "script_near_off_mm", 1, "15", "mm",
              "run_case runs the case once more with the off-path holds this "
              "far off the path, where the law's force stays under the "
              "limits (the RM settles 1-3 mm off), to try the off-path "
              "claims in the linear regime; 0: no such run",
              [](CaseParams* p, const ParamValue& v) {
                p->script.near_off_mm = item(v);
              })
          .non_negative(),
      numeric("script", "script_below_dir", 3, "-0.35 -0.2 0.65", "-",
              "run_case runs the case once more from below the pivot, with "
              "this device-frame direction in place of script_dir (on both "
              "sides: its x as given and negated; script_axis's y negated "
              "when set). script_dir's own y negated would point the stylus "
              "down and forward, where the sphere cases hold the gimbal's q5 "
              "on its -1.13 rad stop and the hand's wrist torque drives the "
              "RM off the path through it; 0 0 0: no runs below",
              [](CaseParams* p, const ParamValue& v) {
                p->script.below_dir = vec3(v);
              }),
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
          .non_negative()
          .at_most(1.0)
          .note("0 0, or 0 < min <= max; max / the physics step <= 1000000"),
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
      numeric("sim", "safety_layer", 1, "0", "-",
              "1: the simulated loop runs behind the device's safety layer "
              "with the limits hw run uses (force ramp, force, torque and "
              "impulse clamps, velocity and thermal cuts; docs/safety.md); "
              "0: no limits beyond the controller's own saturation, as in "
              "the thesis",
              [](CaseParams* p, const ParamValue& v) {
                p->sim.safety_layer = flag(v);
              })
          .flag01(),
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
          .positive()
          .source("van Beek et al. (2015), the fit of one trial of a whole-arm grasp (docs/sources.md, 10); a stylus in a pen grip: 0.20-0.27 kg, 0.14-0.57 over 95% of 15 subjects and 1-3 N grips (Fu & Cavusoglu 2012, at second hand; docs/sources.md, 10.1)"),
      numeric("hand", "hand_inertia_kgm2", 3, "2e-4 2e-4 2e-4", "kg m^2",
              "hand rotational inertia about the grip, stylus axes",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.inertia_kgm2 = vec3(v);
              })
          .positive()
          .source("estimate (models/hand/README.md); no pen-grip measurement found (docs/sources.md, 10.1)"),
      numeric("hand", "hand_k_pos_N_per_m", 1, "135", "N/m",
              "hand translational stiffness (van Beek et al. 2015)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.k_pos_N_per_m = item(v);
              })
          .non_negative()
          .source("van Beek et al. (2015), one trial (docs/sources.md, 10); a pen grip reduced to one stage: 65, 88, 201 N/m along x, y, z, 49-353 over the 95% intervals (Fu & Cavusoglu 2012, at second hand; docs/sources.md, 10.1)"),
      numeric("hand", "hand_b_pos_Ns_per_m", 1, "6.45", "N s/m",
              "hand translational damping (van Beek et al. 2015)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.b_pos_Ns_per_m = item(v);
              })
          .non_negative()
          .source("van Beek et al. (2015), one trial (docs/sources.md, 10); a pen grip: 3.2, 4.6, 9.9 N s/m along x, y, z, about 2.5-16 (Fu & Cavusoglu 2012); 12.6-15.8 along a pen-held stylus (Israr, Choi & Tan 2006) (docs/sources.md, 10.1)"),
      numeric("hand", "hand_k_pos_axes_N_per_m", 3, "0 0 0", "N/m",
              "hand translational stiffness along the device frame's x "
              "(left-right), y (up-down) and z (fore-aft), in place of "
              "hand_k_pos_N_per_m; 0 0 0: hand_k_pos_N_per_m on every axis",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.k_pos_axes_N_per_m = vec3(v);
              })
          .non_negative()
          .source("a stylus in a pen grip reduced to one stage: 65 88 201 N/m (Fu & Cavusoglu 2012, at second hand; docs/sources.md, 10.1)"),
      numeric("hand", "hand_b_pos_axes_Ns_per_m", 3, "0 0 0", "N s/m",
              "hand translational damping along the device frame's x, y and "
              "z, in place of hand_b_pos_Ns_per_m; 0 0 0: "
              "hand_b_pos_Ns_per_m on every axis",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.b_pos_axes_Ns_per_m = vec3(v);
              })
          .non_negative()
          .source("a pen grip reduced to one stage: 3.2 4.6 9.9 N s/m (Fu & Cavusoglu 2012, at second hand; docs/sources.md, 10.1)"),
      numeric("hand", "hand_k_rot_Nm_per_rad", 1, "0.5", "N m/rad",
              "hand rotational stiffness (estimate, models/hand/README.md)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.k_rot_Nm_per_rad = item(v);
              })
          .non_negative()
          .source("estimate (models/hand/README.md); derived, not measured: a pen grip's roll 0.075-0.16 and tilt 0.4-0.6 N m/rad, a relaxed wrist 1.2-1.8 (Formica et al. 2012) (docs/sources.md, 10.1)"),
      numeric("hand", "hand_b_rot_Nms_per_rad", 1, "0.02", "N m s/rad",
              "hand rotational damping (estimate, models/hand/README.md)",
              [](CaseParams* p, const ParamValue& v) {
                p->hand.b_rot_Nms_per_rad = item(v);
              })
          .non_negative()
          .source("estimate (models/hand/README.md); no measured rotational damping of a pen grip found (docs/sources.md, 10.1)"),
  };
  return fields;
}

}  // namespace vmh::sim
