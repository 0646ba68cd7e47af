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
//
// The controller's options (--vm, --kpos, --kv, --weights, ...) are not
// defined here: each is a parameter of the case table (sim/cases/case_params.h,
// docs/parameters.md) with the same name, meaning, default and checks as the
// scene's <custom> field, and both build ControllerParams with
// sim::controller_params. --kv is K_v on the position rows only (as a
// scene's k_vel_Ns_per_mm); --kv-ornt is the orientation rows' (until the
// table, --kv also set those to kv x 2 pi L).
#include "cli/ctl.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli/args.h"
#include "runtime/json_util.h"
#include "controller/controller.h"
#include "controller/device_frame.h"
#include "sim/cases/case_params.h"

namespace vmh::cli {

namespace {

// The controller's options are the table's (sim/cases/case_params.h): one CLI
// option per parameter with a ctl_option, its value as text, checked by the
// same loader as a scene's. Only what is not a parameter is ctl's own.
struct CtlOptions {
  std::vector<std::string> values;    // per row of case_fields()
  std::vector<CLI::Option*> options;  // per row; nullptr: no ctl option
  std::string ticks = "1";
  std::string q;
  std::string convention = "dh";
};

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

// The option behind a ControllerParams::validate message ("controller
// parameter <field>: ..."), "" if none.
std::string option_for_field(const std::string& message) {
  const sim::ParamSpec* p = sim::param_of_validate_message(message);
  return p != nullptr && p->ctl_option != nullptr ? p->ctl_option : "";
}

// the controller's length unit as a name: "mm", "m", or "x<U>mm"
std::string unit_name(double unit_mm) {
  if (unit_mm == 1.0) return "mm";
  if (unit_mm == 1000.0) return "m";
  char buf[64];
  std::snprintf(buf, sizeof buf, "x%.15gmm", unit_mm);
  return buf;
}

// The controller's parameters from the options: the table's loader, then
// the one function scenes use too (sim::controller_params).
ControllerParams read_params(const CtlOptions& o) {
  const std::vector<sim::ParamSpec>& table = sim::case_fields();
  std::vector<std::pair<std::string, std::string>> given;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const CLI::Option* opt = o.options[i];
    if (opt != nullptr && opt->count() > 0) {
      given.emplace_back(table[i].ctl_option, o.values[i]);
    }
  }
  try {
    return sim::controller_params(
        sim::load_case_params("ctl", sim::ctl_inputs(given)));
  } catch (const sim::ParamError& e) {
    throw UsageError(e.what());
  }
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
  const std::vector<sim::ParamSpec>& table = sim::case_fields();
  o->values.resize(table.size());
  o->options.assign(table.size(), nullptr);
  for (std::size_t i = 0; i < table.size(); ++i) {
    const sim::ParamSpec& f = table[i];
    if (f.ctl_option == nullptr) continue;
    std::string help = std::string(f.doc);
    if (std::string(f.unit) != "-") help += " (" + std::string(f.unit) + ")";
    if (f.size > 1) {
      help += "; " + std::to_string(f.size) + " values, comma-separated";
    }
    help += "; default " +
            std::string(f.ctl_default != nullptr ? f.ctl_default
                                                 : f.default_text()) +
            "; scene/--set: " + f.name;
    // (add_flag's second argument would be taken as the flag's variable)
    o->options[i] = f.ctl_flag
                        ? cmd->add_flag(f.ctl_option)->description(help)
                        : cmd->add_option(f.ctl_option, o->values[i], help);
  }
  cmd->add_option("--ticks", o->ticks,
                  "ticks on the same q (warm start); the last is printed; "
                  "default 1");
  cmd->callback([o] { run_ctl(*o); });
}

}  // namespace vmh::cli
