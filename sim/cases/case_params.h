// A case's parameters as typed members, and the one table they come from.
//
// Every parameter is defined once, in case_fields(): its name (the scene's
// <custom> name and the `--set name=` name), type and size, default, unit,
// valid range, meaning, `vmhaptics ctl` option (if any) and a binding to its
// typed member of CaseParams. The loader, the validation, ctl's options and
// docs/parameters.md (`vmhaptics params`) are all made from that table.
//
// Values arrive as text, each with where it came from (a scene file, `--set`
// or a ctl option), are checked once here, and are then read as typed
// members: nobody looks a parameter up by its name after loading.
//
// This header and its source need no MuJoCo: `ctl` uses them without a
// scene. The reading of a scene's <custom> fields is in sim/cases/case_config.h.
#ifndef VMHAPTICS_SIM_CASES_CASE_PARAMS_H_
#define VMHAPTICS_SIM_CASES_CASE_PARAMS_H_

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "controller/controller.h"
#include "controller/omni_ratings.h"
#include "controller/types.h"
#include "sim/fault_injector.h"

namespace vmh::sim {

// A bad parameter: the message names where it came from (file, `--set` or
// a ctl option) and the field.
struct ParamError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The bounds on a run's counts, which ClosedLoop checks when it is made (a
// SimError naming the parameters otherwise) and the table's range notes
// name. Physics steps per servo tick: servo_period_s / the physics step,
// and with servo jitter its longest period / the step, a whole number in
// [1, kMaxSubstepsPerTick] (the precision study's finest step is T / 500).
// Ticks per run: duration_s / servo_period_s, in [1, kMaxTicksPerRun]; the
// table's ranges (duration_s <= 3600 s, servo_period_s >= 1e-5 s) keep it
// below 3.6e8.
inline constexpr std::int64_t kMaxSubstepsPerTick = 1000000;
// the longest delay line of the simulated device, servo ticks
inline constexpr int kMaxDelayTicks = 64;
inline constexpr std::int64_t kMaxTicksPerRun = 1000000000;

// Where a value came from.
enum class ValueSource { kDefault, kScene, kOverride };
const char* value_source_name(ValueSource s);  // default, scene, set

enum class IntegratorSetting { kScene, kEuler, kImplicit, kRk4 };
enum class ScriptKind { kThesis, kHold, kPivot, kSpin };

// The controller's settings, shared by scenes and `ctl`. Device frame, mm.
// No defaults here: the loader fills every member from the table.
struct ControllerSettings {
  VmKind vm_kind{};
  Vec3 vm_pivot_mm = Vec3::Zero();
  double vm_length_mm{};
  double friction_mu{};  // surface only; +inf: never slides
  bool unilateral{};     // surface only
  double k_pos_N_per_mm{};
  double k_ornt_multiple{};  // K_ornt = multiple x 2 pi L (eq. 3.28)
  double k_vel_Ns_per_mm{};          // K_v, position rows
  double k_vel_ornt_Nmms_per_rad{};  // K_v, orientation rows
  Vec6 placement_weights = Vec6::Zero();
  Vec6 projection_weights = Vec6::Zero();
  double length_unit_mm{};
  ErrorFormulation error{};
  PlacementMethod placement{};
  double servo_period_s{};
  double force_limit_N{};
  TorqueLimits torque_limits = TorqueLimits::kOpenHapticsSamples;  // controller/omni_ratings.h
};

// The simulator's settings around the controller.
struct SimSettings {
  double physics_step_s{};  // 0: keep the scene's
  IntegratorSetting integrator{};  // kScene: keep the scene's
  int delay_ticks{};
  bool quantize{};
  double jitter_min_s{}, jitter_max_s{};  // both 0: no jitter
  std::uint64_t jitter_seed{};
  SensorFaultKind fault{};
  int fault_joint{};  // 1..6
  double fault_at_s{};
  bool safety_layer{};  // the loop behind device/safety.h's SafetyLayer
  bool sensor_guard{};
  double guard_max_speed_rad_s{};
  bool gimbal_limits{};
  double duration_s{};
};

// The simulated hand's impedance (models/hand/README.md).
struct HandSettings {
  double mass_kg{};
  Vec3 inertia_kgm2 = Vec3::Zero();
  double k_pos_N_per_m{};
  double b_pos_Ns_per_m{};
  // per device-frame axis (x left-right, y up-down, z fore-aft) in place of
  // the two above; zero: the scalar on every axis
  Vec3 k_pos_axes_N_per_m = Vec3::Zero();
  Vec3 b_pos_axes_Ns_per_m = Vec3::Zero();
  double k_rot_Nm_per_rad{};
  double b_rot_Nms_per_rad{};
};

// The hand script (sim/hand_script.h). Device frame.
struct ScriptSettings {
  ScriptKind kind{};
  std::string name;  // thesis, hold, pivot or spin
  Vec3 dir = Vec3::Zero();
  Vec3 axis = Vec3::Zero();  // 0 0 0: along dir
  double off_mm{};
  // run_case's run near the path, for the off-path claims in the linear
  // regime: the hand target this far off (mm); 0: no such run
  double near_off_mm{};
  // run_case's start direction below the pivot (device frame, run on both
  // sides: x as given and negated); zero: no runs below
  Vec3 below_dir = Vec3::Zero();
  double misalign_rad{};
  double sweep_mm{};
  double sweep_rad{};
};

// One parameter's value as given, and where from (summary.json reports it).
struct ParamValue {
  std::string text;             // text parameters
  std::vector<double> numbers;  // numeric parameters
  ValueSource source = ValueSource::kDefault;
  std::string where;  // the file, "--set" or the ctl option, for messages
  bool set = false;
};

struct ParamSpec;

struct CaseParams {
  int thesis_case{};
  ControllerSettings controller;
  SimSettings sim;
  HandSettings hand;
  ScriptSettings script;

  // the scene file (or "ctl")
  const std::string& scene_path() const { return source; }
  // the value of one table row, as given (summary.json); `spec` must be an
  // element of case_fields()
  const ParamValue& value(const ParamSpec& spec) const;

  std::string source;
  std::vector<ParamValue> values;  // one per row of case_fields()
};

// The check on a numeric parameter, item by item. kPositive and
// kNonNegative may also have a maximum (ParamSpec::has_max: <= hi).
enum class ParamRule {
  kAny,
  kPositive,     // > 0
  kNonNegative,  // >= 0
  kWhole,        // whole number in [lo, hi]
  kInRange,      // in [lo, hi]
};

// One row of the table.
struct ParamSpec {
  const char* name;
  bool is_text;
  int size;                   // number of values (numeric parameters)
  const char* default_value;  // nullptr: required
  const char* unit;
  const char* doc;
  const char* group;  // controller, sim, hand, script, case
  ParamRule rule = ParamRule::kAny;
  double lo = 0.0, hi = 0.0;   // kWhole, kInRange; has_max: hi
  bool has_max = false;        // kPositive, kNonNegative: also <= hi
  bool allow_inf = false;      // +inf is a valid value
  const char* words = nullptr; // text: the valid values, ", "-separated
  const char* range_note = nullptr;  // a rule beyond `rule`, for the docs
  // where the default comes from (a publication and its section of
  // docs/sources.md, or "estimate"), with the published spread where there
  // is one; summary.json and docs/parameters.md carry it
  const char* reference = nullptr;
  // the default when vm_kind is surface, if different
  const char* surface_default = nullptr;
  // `vmhaptics ctl`: the option (nullptr: none), its default if the
  // parameter has none, whether it is a flag (0 or 1 without a value)
  const char* ctl_option = nullptr;
  const char* ctl_default = nullptr;
  bool ctl_flag = false;
  void (*bind)(CaseParams*, const ParamValue&) = nullptr;

  // the range as text: "> 0", "> 0 and <= 3600", "a whole number in [0,
  // 64]", "circle, sphere, surface"; with "each " for a vector and the note
  std::string range_text() const;
  // the rule alone, for one item: "> 0 and <= 3600"; "" for kAny and text
  std::string rule_text() const;
  // the default as text, with the surface's and ctl's where they differ
  std::string default_text() const;
};
using FieldSpec = ParamSpec;  // the older name

// The table of every known parameter.
const std::vector<ParamSpec>& case_fields();
// nullptr when no parameter has that name
const ParamSpec* find_param(const std::string& name);
// all names, ", "-separated, for messages
std::string param_names();

// Checks one item of a numeric parameter against its row's rule; throws
// ParamError "<where>: field '<name>' must be <rule_text>, got <x>" (x as
// %.9g, so 1e-7 shows as 1e-07). Finiteness is the loader's (store) check.
void check_param_number(const ParamSpec& spec, double x, const std::string& where);

// One value as text, with where it came from. `where` names the file,
// "--set" or the ctl option in messages.
struct ParamInput {
  std::string name;
  std::string value;
  ValueSource source = ValueSource::kOverride;
  std::string where;
};

// "name=value" items of `--set` (vectors comma- or space-separated) as
// inputs; throws ParamError on a missing '=' or an unknown name.
std::vector<ParamInput> set_inputs(const std::vector<std::string>& sets);

// The inputs of `vmhaptics ctl`'s options: (option, value) pairs as given
// on the command line (a flag's value is ignored: giving it means 1), then
// the ctl defaults (ParamSpec::ctl_default) of those not given. Throws
// ParamError on an option the table does not have.
std::vector<ParamInput> ctl_inputs(
    const std::vector<std::pair<std::string, std::string>>& given);

// Reads `inputs` in order (a later one replaces an earlier one of the same
// name), fills what none gives with the defaults, checks every value and
// returns the typed parameters. `source` names the case in messages about a
// missing parameter. Throws ParamError naming where and the field.
CaseParams load_case_params(const std::string& source,
                            const std::vector<ParamInput>& inputs);

// One <custom> field of a scene: its name, whether it is a <text>, and its
// value as text (a <numeric>'s numbers space-separated, full precision)
struct CustomField {
  std::string name;
  bool is_text = false;
  std::string value;
};

// A scene's case parameters from its <custom> fields (read by MuJoCo,
// sim/cases/case_config.h, or without it, sim/cases/scene_fields.h), with `overrides`
// ("name=value", --set) on top. Every field must be one the table knows,
// under its kind's tag: a number written as <text> (or a word as
// <numeric>) would otherwise be skipped and its default used without a
// word. Throws ParamError naming `source` (the scene file) and the field.
CaseParams case_params_from_fields(const std::vector<CustomField>& fields,
                                   const std::string& source,
                                   const std::vector<std::string>& overrides);

// The controller's parameters: the one route from settings to
// ControllerParams for scenes and `ctl`.
ControllerParams controller_params(const ControllerSettings& s);
inline ControllerParams controller_params(const CaseParams& c) {
  return controller_params(c.controller);
}
// A case's controller as the device it runs on sees it: controller_params,
// with the gimbal's ranges opened to +-pi when the case has no gimbal
// limits (gimbal_limits = 0: the wrist free to turn through its
// singularity). What the simulated loop and `hw run` both run.
ControllerParams case_controller_params(const CaseParams& c);

// The parameter behind a ControllerParams::validate message ("controller
// parameter <field>: ..."); nullptr if none.
const ParamSpec* param_of_validate_message(const std::string& message);

// The table as Markdown (docs/parameters.md is this, verbatim).
std::string parameters_markdown();

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CASES_CASE_PARAMS_H_
