// `vmhaptics ctl ...`: the virtual-mechanism controller (thesis ch. 3) run
// at one joint configuration, as one JSON object on stdout. The field names
// and units are a contract documented in docs/outputs.md.
//
// The controller is ticked --ticks times on the same q (the warm start of
// the Gauss-Newton placement is what repeats); the last tick is printed.
// A single tick has no previous error, so e_dot is 0.
//
// A controller fault (vmh::is_fault, e.g. a NaN joint angle) still prints
// the JSON, so that scripts can read the status, and then fails with exit
// code 1 and one line on stderr.
#include "cli/ctl.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli/args.h"
#include "cli/json_util.h"
#include "controller/controller.h"
#include "controller/device_frame.h"

namespace vmh::cli {

namespace {

struct CtlOptions {
  std::string vm = "circle";
  std::string pivot_mm = "0,0,0";
  std::string length_mm = "50";
  std::string kpos = "0.5";
  std::string kornt = "0";
  std::string kv = "0";
  std::string error = "thesis";
  std::string placement = "gauss-newton";
  std::string weights;  // empty: the default for the VM
  std::string length_unit_mm = "1";
  std::string mu = "0";
  bool unilateral = false;
  std::string ticks = "1";
  std::string q;
  std::string convention = "dh";
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::string lower(std::string s) {
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> items;
  std::string::size_type start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    items.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

// "nan", "inf", "-inf", ... as a number; false for anything else (including
// finite numbers)
bool parse_non_finite(const std::string& raw, double* v) {
  const std::string item = trim(raw);
  if (item.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(item.c_str(), &end);
  if (end == item.c_str() || *end != '\0' || std::isfinite(x)) return false;
  // strtod also overflows "1e999" to inf: that is a typo, not a sensor fault
  if (errno == ERANGE) return false;
  *v = x;
  return true;
}

// The joint angles, NaN and inf allowed: the controller, not the command
// line, reports a non-finite sensor reading (status invalid_input). Every
// other mistake is the usual usage error of parse_list.
Joints parse_joints(const std::string& option, const std::string& text) {
  std::vector<std::string> items = split(text);
  std::vector<std::pair<std::size_t, double>> special;
  std::string finite_text;
  for (std::size_t i = 0; i < items.size(); ++i) {
    double v = 0.0;
    if (parse_non_finite(items[i], &v)) {
      special.emplace_back(i, v);
      items[i] = "0";
    }
    finite_text += (i == 0 ? "" : ",") + items[i];
  }
  std::vector<double> values = parse_list(option, finite_text, kOmniJoints);
  for (const auto& [i, v] : special) values[i] = v;
  Joints q;
  for (int i = 0; i < kOmniJoints; ++i)
    q[i] = values[static_cast<std::size_t>(i)];
  return q;
}

Vec3 parse_vec3(const std::string& option, const std::string& text) {
  const std::vector<double> v = parse_list(option, text, 3);
  return Vec3(v[0], v[1], v[2]);
}

Vec6 parse_vec6(const std::string& option, const std::string& text) {
  const std::vector<double> v = parse_list(option, text, 6);
  Vec6 out;
  for (int i = 0; i < 6; ++i) out[i] = v[static_cast<std::size_t>(i)];
  return out;
}

// a finite number, or "inf" (never slides)
double parse_mu(const std::string& text) {
  const std::string t = lower(trim(text));
  if (t == "inf" || t == "+inf" || t == "infinity" || t == "+infinity") {
    return std::numeric_limits<double>::infinity();
  }
  return parse_number("--mu", text);
}

int parse_ticks(const std::string& text) {
  const double v = parse_number("--ticks", text);
  if (v < 1.0 || v > 1e6 || v != std::floor(v)) {
    throw UsageError(
        "--ticks: expected a whole number from 1 to 1000000, "
        "got '" +
        trim(text) + "'");
  }
  return static_cast<int>(v);
}

[[noreturn]] void unknown_value(const std::string& option,
                                const std::string& value,
                                const std::string& allowed) {
  throw UsageError(option + ": unknown value '" + value +
                   "' (expected one of: " + allowed + ")");
}

// The command-line option behind a ControllerParams field, for the message
// of ControllerParams::validate ("controller parameter <field>: ...").
std::string option_for_field(const std::string& message) {
  static const std::pair<const char*, const char*> kFields[] = {
      {"vm.pivot_mm", "--pivot-mm"},
      {"vm.length_mm", "--length-mm"},
      {"vm.friction_mu", "--mu"},
      {"gains.k_pos_N_per_mm", "--kpos"},
      {"gains.k_ornt_Nmm_per_rad", "--kornt"},
      {"gains.k_vel_Ns_per_mm", "--kv"},
      {"gains.k_vel_ornt_Nmms_per_rad", "--kv"},
      {"placement_options.weights", "--weights"},
      {"length_unit_mm", "--length-unit-mm"},
  };
  const std::string prefix = "controller parameter ";
  if (message.rfind(prefix, 0) != 0) return "";
  const std::string field =
      message.substr(prefix.size(), message.find(':') - prefix.size());
  for (const auto& [name, option] : kFields) {
    if (field == name) return option;
  }
  return "";
}

// the controller's length unit as a name: "mm", "m", or "x<U>mm"
std::string unit_name(double unit_mm) {
  if (unit_mm == 1.0) return "mm";
  if (unit_mm == 1000.0) return "m";
  char buf[64];
  std::snprintf(buf, sizeof buf, "x%.15gmm", unit_mm);
  return buf;
}

ControllerParams read_params(const CtlOptions& o) {
  ControllerParams p;
  if (!parse_vm_kind(o.vm.c_str(), &p.vm.kind)) {
    unknown_value("--vm", o.vm, "circle, sphere, surface");
  }
  if (!parse_error_formulation(o.error.c_str(), &p.error)) {
    unknown_value("--error", o.error, "thesis, geometric");
  }
  if (!parse_placement_method(o.placement.c_str(), &p.placement)) {
    unknown_value("--placement", o.placement, "gauss-newton, closed");
  }
  p.vm.pivot_mm = parse_vec3("--pivot-mm", o.pivot_mm);
  p.vm.length_mm = parse_number("--length-mm", o.length_mm);
  p.vm.friction_mu = parse_mu(o.mu);
  p.vm.unilateral = o.unilateral;
  const double L = p.vm.length_mm;
  p.gains.k_pos_N_per_mm = parse_number("--kpos", o.kpos);
  p.gains.k_ornt_Nmm_per_rad =
      thesis_orientation_gain(parse_number("--kornt", o.kornt), L);
  const double kv = parse_number("--kv", o.kv);
  p.gains.k_vel_Ns_per_mm = kv;
  // by analogy with eq. 3.28: the same multiple of the circumference
  p.gains.k_vel_ornt_Nmms_per_rad = thesis_orientation_gain(kv, L);
  if (o.weights.empty()) {
    p.placement_options.weights = p.vm.kind == VmKind::kSurface
                                      ? Vec6::Ones().eval()
                                      : (Vec6() << 1, 1, 1, 0, 0, 0).finished();
  } else {
    p.placement_options.weights = parse_vec6("--weights", o.weights);
  }
  p.length_unit_mm = parse_number("--length-unit-mm", o.length_unit_mm);
  return p;
}

Json angles_json(const VmAngles& theta) {
  // empty when the tick faulted before placing the VM
  return theta.size() > 0 ? to_json_vector(theta) : Json(nullptr);
}

void run_ctl(const CtlOptions& o) {
  const ControllerParams params = read_params(o);
  const int ticks = parse_ticks(o.ticks);
  Joints q = parse_joints("--q", o.q);
  if (o.convention == "device") q = device_to_dh_joints(q);

  std::unique_ptr<Controller> ctl;
  try {
    ctl = std::make_unique<Controller>(params);
  } catch (const std::invalid_argument& e) {
    const std::string option = option_for_field(e.what());
    throw UsageError((option.empty() ? std::string("ctl") : option) + ": " +
                     e.what());
  }
  ControlOutput out;
  for (int i = 0; i < ticks; ++i) ctl->tick(q, &out);

  const double u = params.length_unit_mm;
  const std::string unit = unit_name(u);
  // quantities the controller did not compute on invalid input are null
  const bool computed = (out.status & kStatusInvalidInput) == 0;
  const auto maybe = [computed](Json j) {
    return computed ? std::move(j) : Json(nullptr);
  };

  Json j;
  j["vm"] = vm_kind_name(params.vm.kind);
  j["q_dh"] = to_json_vector(q);
  j["q_device"] = to_json_vector(dh_to_device_joints(q));
  j["error_formulation"] = error_formulation_name(params.error);
  j["placement"] = placement_method_name(params.placement);
  j["length_unit_mm"] = u;
  j["gains"] = {
      {"k_pos_N_per_mm", params.gains.k_pos_N_per_mm},
      {"k_ornt_Nmm_per_rad", params.gains.k_ornt_Nmm_per_rad},
      {"k_vel_Ns_per_mm", params.gains.k_vel_Ns_per_mm},
      {"k_vel_ornt_Nmms_per_rad", params.gains.k_vel_ornt_Nmms_per_rad}};
  j["p_rm_mm"] = maybe(to_json_vector(out.p_rm_mm));
  j["axis_rm"] = maybe(to_json_vector(out.axis_rm));
  j["theta_v"] = maybe(angles_json(out.theta_v));
  j["theta_r"] = maybe(angles_json(out.theta_r));
  j["x_v_mm"] = maybe(to_json_vector(out.x_v_mm));
  j["x_r_mm"] = maybe(to_json_vector(out.x_r_mm));
  j["e"] = to_json_vector(out.e);
  j["e_units"] = {unit, unit, unit, "rad", "rad", "rad"};
  j["e_dot"] = to_json_vector(out.e_dot);
  j["f_motion"] = to_json_vector(out.f_motion);
  const std::string torque = "N*" + unit;
  j["f_motion_units"] = {"N", "N", "N", torque, torque, torque};
  j["force_device_N"] = to_json_vector(out.force_device_N);
  j["force_base_N"] = to_json_vector(out.force_base_N);
  j["tau_Nm"] = to_json_vector(out.tau_dh_Nm);
  j["tau_motor_Nm"] = to_json_vector(out.tau_motor_Nm);
  j["placement_iterations"] = out.placement_iterations;
  j["placement_cost"] = out.placement_cost;
  j["vm_rcond"] = out.vm_rcond;
  Json status = Json::array();
  std::string status_text;
  for (int b = 0; b < kStatusFlagCount; ++b) {
    const ControlStatus bit = ControlStatus{1} << b;
    if ((out.status & bit) == 0) continue;
    status.push_back(status_flag_name(bit));
    status_text +=
        (status_text.empty() ? "" : ", ") + std::string(status_flag_name(bit));
  }
  if (status.empty()) status.push_back(status_flag_name(kStatusOk));
  j["status"] = std::move(status);
  j["status_code"] = out.status;
  std::cout << dump_readable(j) << '\n' << std::flush;

  if (is_fault(out.status)) {
    throw std::runtime_error("ctl: controller fault (" + status_text +
                             "): force and torques are zero");
  }
}

}  // namespace

void register_ctl(CLI::App* app) {
  auto o = std::make_shared<CtlOptions>();
  CLI::App* cmd = app->add_subcommand(
      "ctl",
      "one tick of the virtual-mechanism controller (ch. 3) at a joint "
      "configuration, JSON on stdout");
  cmd->add_option("--q", o->q,
                  "six joint angles q1,...,q6 (rad); nan/inf are passed to "
                  "the controller, which reports invalid_input")
      ->required();
  cmd->add_option("--convention", o->convention,
                  "joint angles given as 'dh' (thesis Table B.1, q3 "
                  "relative) or 'device' (OpenHaptics, joint 3 absolute)")
      ->check(CLI::IsMember({"dh", "device"}));
  cmd->add_option("--vm", o->vm,
                  "virtual mechanism: circle (1 DOF), sphere (3) or surface "
                  "(5); default circle");
  cmd->add_option("--pivot-mm", o->pivot_mm,
                  "pivot (circle, sphere) or a point of the plane (surface), "
                  "x,y,z in the device frame (mm); default 0,0,0");
  cmd->add_option("--length-mm", o->length_mm,
                  "VM link length L (mm); default 50");
  cmd->add_option("--kpos", o->kpos, "position gain K_pos (N/mm); default 0.5");
  cmd->add_option("--kornt", o->kornt,
                  "orientation gain as a multiple of the circumference "
                  "(eq. 3.28): K_ornt = kornt * 2 pi L (N mm/rad); default 0");
  cmd->add_option("--kv", o->kv,
                  "velocity gain (N s/mm); the orientation rows get kv * 2 pi "
                  "L (N mm s/rad); default 0");
  cmd->add_option("--error", o->error,
                  "error formulation: thesis (eq. 3.32-3.37) or geometric; "
                  "default thesis");
  cmd->add_option("--placement", o->placement,
                  "VM placement: gauss-newton (eq. 3.15-3.16) or closed; "
                  "default gauss-newton");
  cmd->add_option("--weights", o->weights,
                  "placement weights w1,...,w6 (x,y,z,theta_x,theta_y,"
                  "theta_z); default 1,1,1,0,0,0 (circle, sphere) or "
                  "1,1,1,1,1,1 (surface)");
  cmd->add_option("--length-unit-mm", o->length_unit_mm,
                  "the controller's length unit in mm: 1 = mm (thesis), "
                  "1000 = m; default 1");
  cmd->add_option("--mu", o->mu,
                  "surface: Coulomb friction of the contact, >= 0 or inf; "
                  "default 0 (slides freely)");
  cmd->add_flag("--unilateral", o->unilateral,
                "surface: the plane only pushes; the probe may lift off");
  cmd->add_option("--ticks", o->ticks,
                  "ticks on the same q (warm start); the last is printed; "
                  "default 1");
  cmd->callback([o] { run_ctl(*o); });
}

}  // namespace vmh::cli
