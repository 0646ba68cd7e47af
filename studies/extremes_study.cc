#include "studies/extremes_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "report/output_file.h"
#include "report/parallel.h"
#include "studies/run_case.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace fs = std::filesystem;
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string vec_text(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g", v.x(), v.y(), v.z());
  return buf;
}

// a field's default from the case table, as a vector
Vec3 default_vec3(const char* name) {
  for (const FieldSpec& f : case_fields()) {
    if (std::string(f.name) != name) continue;
    std::istringstream in(f.default_value);
    Vec3 v;
    in >> v.x() >> v.y() >> v.z();
    return v;
  }
  throw SimError(std::string("no case field ") + name);
}

// The start point of the circle cases (pivot at the origin, L = 50 mm, the
// default script_dir projected on the device x-y plane), and the forearm's
// direction there (z4 of Table B.1: elbow to wrist centre, device frame) on
// the IK branch nearest the home pose. With q5 = +pi/2 the stylus axis z6 is
// -z4: the pen continues the forearm, tip away from the elbow.
Vec3 circle_start_mm() {
  Vec3 dir = default_vec3("script_dir");
  dir.z() = 0.0;
  return 50.0 * dir.normalized();
}

Vec3 forearm_axis_device(const Vec3& p_mm) {
  const OmniParams omni;
  const IkSolutions ik =
      omni_ik_position(omni, device_mm_to_base(omni, p_mm), Joints::Zero());
  const int k = omni_ik_nearest(ik, Joints::Zero());
  if (k < 0) throw SimError("extremes: the circle's start point is unreachable");
  OmniFrames frames;
  omni_frames(omni, ik.q_dh[static_cast<std::size_t>(k)], &frames);
  return base_to_device_vector(frames.T_base[4].linear().col(2));
}

// A pose at the edge of the workspace: the elbow 0.05 rad short of where
// its range ends (q3 = 1.25 rad puts the wrist centre 263.3 mm from the
// shoulder, of the 266.7 mm l1 + l2; full stretch, q3 = pi/2, lies outside
// the range), the upper arm 0.3 rad below level, the wrist centre in front
// of the shoulder. The script then pulls 60 mm further out.
struct EdgePose {
  Vec3 p_mm;       // wrist centre, device frame
  Vec3 out_dir;    // from the shoulder through it
  Vec3 axis;       // stylus axis with the gimbal at zero
};

EdgePose edge_pose() {
  const OmniParams omni;
  Joints q = Joints::Zero();
  q[1] = -0.3;
  q[2] = omni.joint_upper_rad[2] - 0.05;
  const OmniPose pose = omni_fk(omni, q);
  EdgePose e;
  e.p_mm = base_to_device_mm(omni, pose.p_base_m);
  e.out_dir = (e.p_mm - base_to_device_mm(omni, Vec3::Zero())).normalized();
  e.axis = base_to_device_vector(pose.R_base.col(2));
  return e;
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

// every output of a tick that must stay finite (the reading itself may be
// NaN by injection and is checked apart)
const char* nonfinite_part(const TraceRow& r) {
  const ControlOutput& o = r.out;
  if (!o.force_device_N.allFinite()) return "force_device_N";
  if (!o.tau_motor_Nm.allFinite()) return "tau_motor_Nm";
  if (!o.f_motion.allFinite()) return "f_motion";
  if (!o.e.allFinite()) return "e";
  if (!o.e_dot.allFinite()) return "e_dot";
  if (!o.x_v_mm.allFinite()) return "x_v_mm";
  if (!o.x_r_mm.allFinite()) return "x_r_mm";
  if (!o.p_rm_mm.allFinite()) return "p_rm_mm";
  if (!o.axis_rm.allFinite()) return "axis_rm";
  if (!o.theta_v.allFinite()) return "theta_v";
  if (!o.theta_r.allFinite()) return "theta_r";
  if (!r.motor_torque_Nm.allFinite()) return "motor_torque_Nm";
  if (!r.hand_force_N.allFinite()) return "hand_force_N";
  if (!r.p_true_mm.allFinite()) return "p_true_mm";
  if (!std::isfinite(r.energy_motor_J) || !std::isfinite(r.energy_hand_J) ||
      !std::isfinite(r.kinetic_J)) {
    return "energy";
  }
  if (!r.state_finite) return "mujoco_state";
  return nullptr;
}

}  // namespace

std::vector<ExtremeScenario> extreme_scenarios() {
  const Vec3 p_circle = circle_start_mm();
  const Vec3 along_forearm = -forearm_axis_device(p_circle);
  const EdgePose edge = edge_pose();
  const double L = 50.0;
  // the stylus turned so that its projection on the circle's plane points
  // away from the RM's azimuth: theta_V - theta_R = pi at the start, and the
  // spin script's swing carries it across +-pi
  Vec3 away = -p_circle.normalized();
  away.z() = 0.0;
  const Vec3 axis_opposite = (0.3 * away + Vec3(0.0, 0.0, 1.0)).normalized();

  const std::string x10 = "k_pos_N_per_mm=5", x10o = "k_ornt_multiple=5";
  const std::string x100 = "k_pos_N_per_mm=50", x100o = "k_ornt_multiple=50";
  // the periods are drawn in whole physics steps, so the step must divide
  // 0.4 ms: 0.2 ms here (the scenes' own step is 1 ms)
  const std::string jitter = "servo_jitter_s=0.0004,0.0028";
  const std::string jitter_step = "physics_step_s=0.0002";
  const std::string stiff_hand = "hand_k_pos_N_per_m=5000";

  const std::string flutter =
      "K_ornt x10 makes the orientation term flutter with the estimated wrist "
      "(hand_k_rot 0.5 N m/rad): independent of T, h, quantisation and the "
      "integrator, gone with a stiffer or more damped wrist "
      "(ExtremesStudy.OrientationGainFlutters)";
  std::vector<ExtremeScenario> s;
  auto add = [&s](std::string name, std::string base,
                  std::vector<std::string> overrides, std::string stresses,
                  std::string injected = "none", std::string expected = "",
                  std::string energy = "bounded", std::string why = "") {
    ExtremeScenario e;
    e.name = std::move(name);
    e.base = std::move(base);
    e.overrides = std::move(overrides);
    e.stresses = std::move(stresses);
    e.injected = std::move(injected);
    e.expected = std::move(expected);
    e.energy = std::move(energy);
    e.energy_why = std::move(why);
    s.push_back(std::move(e));
  };
  // every scenario that holds the RM off the path asks for more than 3.3 N
  // (K_pos x 25 mm > 12 N even at the thesis's gains): force_saturated
  add("baseline", "case2", {}, "the thesis's case 2 script in 6 s: the reference", "none", "force_saturated");
  add("gains_x10", "case2", {x10, x10o}, "K_pos and K_ornt x10 of the thesis's", "none", "force_saturated", "limit_cycle", flutter);
  add("gains_x10_position", "case2", {x10}, "K_pos x10 alone", "none", "force_saturated");
  add("gains_x100", "case2", {x100, x100o}, "K_pos and K_ornt x100: one encoder count (0.056 mm) asks for 2.8 N", "none", "force_saturated");
  add("gains_x100_sphere", "case5", {x100}, "the sphere at K_pos x100, no orientation term", "none", "force_saturated");
  add("hand_k_10", "case2", {"hand_k_pos_N_per_m=10"}, "a hand of 10 N/m: the VM drags the stylus", "none", "force_saturated");
  add("hand_k_5000", "case2", {stiff_hand}, "a hand of 5000 N/m against the VM", "none", "force_saturated");
  add("hand_k_5000_gains_x100", "case2", {stiff_hand, x100, x100o}, "the stiffest hand and the stiffest VM", "none", "force_saturated");
  add("hand_rot_0.05", "case2", {"hand_k_rot_Nm_per_rad=0.05", "hand_b_rot_Nms_per_rad=0.002"}, "a limp wrist (rotational stiffness and damping / 10)");
  add("hand_rot_5", "case2", {"hand_k_rot_Nm_per_rad=5"}, "a stiff wrist (rotational stiffness x 10)");
  // the encoders count from the home pose, so at the home pose the reading
  // is the pivot exactly: theta_V undefined on the first ticks
  add("rm_at_pivot_sphere", "case5", {"script=pivot", stiff_hand}, "LL -> 0: the RM held at the sphere's centre, then driven through it", "none", "rm_at_pivot");
  add("rm_at_pivot_circle", "case2", {"script=pivot", stiff_hand}, "the RM at the circle's centre (on its axis), then through it", "none", "rm_at_pivot");
  add("sphere_pole_plus_z", "case6", {"script_dir=0,0,1"}, "the sphere's pole +z with orientation gain: theta_V1, theta_R1 undefined");
  add("sphere_pole_minus_z", "case6", {"script_dir=0,0,-1", "script_axis=0,0.6,0.8"}, "the sphere's pole -z (theta_V2 = 0)");
  add("gimbal_singular", "case2", {"gimbal_limits=0", "script=spin", "script_axis=" + vec_text(along_forearm)}, "the stylus along the forearm (q5 = pi/2), swung through it");
  // the hand pulls 60 mm past full reach: MuJoCo's joint limits are soft, so
  // the elbow passes q3's upper range under the load
  add("stretched_arm", "case5", {"vm_pivot_mm=" + vec_text(edge.p_mm - L * edge.out_dir), "script_dir=" + vec_text(edge.out_dir), "script_axis=" + vec_text(edge.axis)}, "the arm at full reach, pulled 60 mm beyond it", "none", "outside_joint_limits");
  add("orientation_error_pi", "case2", {"script=spin", "script_axis=" + vec_text(axis_opposite), "script_misalign_rad=1", stiff_hand}, "theta_V - theta_R swung across +-pi (the wrap), the RM held on the path");
  add("servo_jitter", "case2", {jitter, jitter_step}, "servo periods drawn from 0.4-2.8 ms, the controller told 1 ms");
  add("servo_jitter_damped", "case2", {jitter, jitter_step, "k_vel_Ns_per_mm=0.005"}, "jitter with K_v: e_dot from the wrong period");
  add("servo_jitter_kpos_x10", "case2", {jitter, jitter_step, x10}, "jitter with K_pos x10: K T/2 against the hand's damping");
  add("fault_nan", "case2", {"fault=nan", "fault_joint=2", "fault_at_s=1"}, "encoder t2 reads NaN from 1 s, guard on", "nan", "sensor_nan");
  add("fault_nan_unguarded", "case2", {"fault=nan", "fault_joint=2", "fault_at_s=1", "sensor_guard=0"}, "the same NaN with the guard off: the controller's own check", "nan", "invalid_input");
  add("fault_jump", "case2", {"fault=jump", "fault_joint=1", "fault_at_s=1"}, "encoder t1 slips +1000 counts at 1 s, guard on", "jump", "sensor_jump");
  add("fault_jump_unguarded", "case2", {"fault=jump", "fault_joint=1", "fault_at_s=1", "sensor_guard=0"}, "the same slip with the guard off: undetectable downstream", "jump");
  add("fault_stuck", "case2", {"fault=stuck", "fault_joint=2", "fault_at_s=1"}, "encoder t2 stuck from 1 s: no check on the readings sees it", "stuck");
  return s;
}

ExtremeResult run_extreme(const ExtremeScenario& s,
                          std::vector<TraceRow>* trace) {
  ExtremeResult r;
  r.scenario = s;
  std::string name;
  const std::string scene = resolve_scene(s.base, &name);
  std::vector<std::string> sets = {"duration_s=" + std::to_string(kExtremeDurationS)};
  sets.insert(sets.end(), s.overrides.begin(), s.overrides.end());
  ClosedLoop loop(scene, sets);

  const mjModel* m = loop.model();
  const ControllerParams& params = loop.controller_params();
  const OmniParams& omni = params.omni;
  r.force_limit_N = params.force_limit_N;
  for (int i = 0; i < 3; ++i) {
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, ("m" + std::to_string(i + 1)).c_str());
    r.motor_limit_Nm[i] = m->actuator_ctrlrange[2 * a + 1];
  }
  const Vec3 shoulder_mm = base_to_device_mm(omni, Vec3::Zero());
  const double reach_mm = 1000.0 * (omni.l1_m + omni.l2_m);
  const double script_end_s = loop.config().number("duration_s");
  const double end_s = script_end_s + kExtremeRestS;

  std::vector<TraceRow> local;
  std::vector<TraceRow>& rows = trace != nullptr ? *trace : local;
  rows.clear();
  rows.reserve(static_cast<std::size_t>(loop.ticks_per_run()));

  const auto start = std::chrono::steady_clock::now();
  while (loop.time_s() < end_s - 0.5 * m->opt.timestep) {
    rows.emplace_back();
    loop.tick(&rows.back());
  }
  r.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.simulated_s = loop.time_s();
  r.ticks = static_cast<int>(rows.size());

  // -- per tick --
  std::set<std::string> statuses, device_errors, guard_faults;
  ControlStatus seen = kStatusOk;
  r.energy_motor_max_J = r.energy_motor_min_J = 0.0;
  r.min_pivot_distance_mm = 1e300;
  r.min_q5_to_singular_rad = 1e300;
  r.min_period_s = 1e300;
  double period_sum = 0.0;
  // the rest's last window
  const double window_from_s = end_s - kRestWindowS;
  bool in_window = false;
  double window_start_J = 0.0;
  double prev_end_J = 0.0;  // the observer at the end of the last tick
  r.min_pole_angle_rad = 1e300;
  const Vec3 pole_axis = params.vm.R_pivot.col(2);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const TraceRow& row = rows[k];
    const int tick = static_cast<int>(k);
    if (r.finite) {
      if (const char* part = nonfinite_part(row)) {
        r.finite = false;
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s at t = %.4f s", part, row.t_s);
        r.first_nonfinite = buf;
      }
    }
    if (!row.q_dh.allFinite()) ++r.nonfinite_reading_ticks;

    // the command as the controller computed it and as the motors held it
    r.max_force_N = std::max(r.max_force_N, row.out.force_device_N.norm());
    for (int i = 0; i < 3; ++i) {
      r.max_motor_torque_Nm[i] =
          std::max(r.max_motor_torque_Nm[i], std::abs(row.motor_torque_Nm[i]));
    }

    // statuses
    if (row.servo.read == DeviceError::kOk) seen |= row.out.status;
    if (row.servo.read != DeviceError::kOk) device_errors.insert(device_error_name(row.servo.read));
    if (row.servo.write != DeviceError::kOk) device_errors.insert(device_error_name(row.servo.write));
    if (row.guard != GuardFault::kNone) guard_faults.insert(guard_fault_name(row.guard));
    if (row.servo.zeroed) ++r.zeroed_ticks;
    const bool fault_named = row.servo.read != DeviceError::kOk ||
                             (row.servo.read == DeviceError::kOk && is_fault(row.out.status));
    if (row.fault_injected && r.fault_tick < 0) r.fault_tick = tick;
    if (r.fault_tick >= 0 && r.detection_tick < 0 && fault_named) r.detection_tick = tick;
    if (r.detection_tick >= 0 && tick >= r.detection_tick) {
      r.max_torque_after_detection_Nm =
          std::max(r.max_torque_after_detection_Nm, row.motor_torque_Nm.cwiseAbs().maxCoeff());
    }

    // energy
    const double E = row.energy_motor_J;
    r.energy_motor_max_J = std::max(r.energy_motor_max_J, E);
    r.energy_motor_min_J = std::min(r.energy_motor_min_J, E);
    r.kinetic_max_J = std::max(r.kinetic_max_J, row.kinetic_J);
    if (row.t_s >= window_from_s) {
      if (!in_window) {
        in_window = true;
        window_start_J = prev_end_J;
      }
      r.rest_energy_rise_J = std::max(r.rest_energy_rise_J, E - window_start_J);
      r.rest_kinetic_max_J = std::max(r.rest_kinetic_max_J, row.kinetic_J);
    }
    prev_end_J = E;
    r.energy_motor_final_J = E;
    r.energy_hand_final_J = row.energy_hand_J;

    // what the scenario reached, from MuJoCo's true angles
    const Vec3 from_pivot = row.p_true_mm - params.vm.pivot_mm;
    r.min_pivot_distance_mm = std::min(r.min_pivot_distance_mm, from_pivot.norm());
    if (from_pivot.norm() > 1e-9) {
      const double c = std::abs(from_pivot.normalized().dot(pole_axis));
      r.min_pole_angle_rad = std::min(r.min_pole_angle_rad, std::acos(std::min(1.0, c)));
    }
    r.max_reach_fraction =
        std::max(r.max_reach_fraction, (row.p_true_mm - shoulder_mm).norm() / reach_mm);
    r.min_q5_to_singular_rad = std::min(
        r.min_q5_to_singular_rad, std::abs(0.5 * kPi - std::abs(wrap_angle(row.q_true_dh[4]))));
    if (k > 0) {
      // encoder speeds over the previous tick, device joints t1..t3
      const TraceRow& prev = rows[k - 1];
      const Joints dq = dh_to_device_joints(row.q_true_dh) - dh_to_device_joints(prev.q_true_dh);
      r.max_encoder_speed_rad_s = std::max(
          r.max_encoder_speed_rad_s, dq.head<3>().cwiseAbs().maxCoeff() / prev.period_s);
      const Vec6 de = row.out.e - prev.out.e;
      for (int i = 3; i < 6; ++i) {
        if (std::abs(de[i]) > kPi) {
          ++r.orientation_wraps;
          break;
        }
      }
    }
    r.min_period_s = std::min(r.min_period_s, row.period_s);
    r.max_period_s = std::max(r.max_period_s, row.period_s);
    period_sum += row.period_s;
  }
  r.mean_period_s = rows.empty() ? 0.0 : period_sum / static_cast<double>(rows.size());

  for (int b = 0; b < kStatusFlagCount; ++b) {
    if (seen & (1u << b)) statuses.insert(status_flag_name(1u << b));
  }
  r.statuses.assign(statuses.begin(), statuses.end());
  r.device_errors.assign(device_errors.begin(), device_errors.end());
  r.guard_faults.assign(guard_faults.begin(), guard_faults.end());
  for (int i = 0; i < mjNWARNING; ++i) r.mujoco_warnings += loop.data()->warning[i].number;

  // -- judgement --
  r.force_within_limit = r.max_force_N <= r.force_limit_N * (1.0 + 1e-12);
  r.torque_within_limit = true;
  for (int i = 0; i < 3; ++i) {
    r.torque_within_limit &= r.max_motor_torque_Nm[i] <= r.motor_limit_Nm[i] * (1.0 + 1e-12);
  }
  r.passive = r.energy_motor_max_J <= kPassiveToleranceJ;
  r.energy_bounded = in_window && r.rest_energy_rise_J <= kRestEnergyRiseBoundJ;

  // Colgate & Schenkel's bound for this scenario's translational gains
  const CaseConfig& c = loop.config();
  const double T_max_s = loop.substeps_max() * m->opt.timestep;
  r.colgate_demand_Ns_per_m = 1000.0 * c.number("k_pos_N_per_mm") * T_max_s / 2.0 +
                              1000.0 * std::abs(c.number("k_vel_Ns_per_mm"));
  r.colgate_b_Ns_per_m = c.number("hand_b_pos_Ns_per_m");
  r.colgate_passive = r.colgate_b_Ns_per_m > r.colgate_demand_Ns_per_m;
  r.energy_expected = s.energy;
  if (r.energy_expected == "bounded" && !r.colgate_passive) r.energy_expected = "either";

  std::vector<std::string> failures;
  if (!r.finite) failures.push_back("nonfinite");
  if (!r.force_within_limit) failures.push_back("force_above_limit");
  if (!r.torque_within_limit) failures.push_back("torque_above_limit");
  if (!r.energy_bounded && r.energy_expected == "bounded") {
    failures.push_back("energy_unbounded");
  }
  if (r.mujoco_warnings > 0) failures.push_back("mujoco_warning");
  std::vector<std::string> named = r.statuses;
  named.insert(named.end(), r.device_errors.begin(), r.device_errors.end());
  named.insert(named.end(), r.guard_faults.begin(), r.guard_faults.end());
  const auto has = [&named](const std::string& n) {
    return std::find(named.begin(), named.end(), n) != named.end();
  };
  if (!s.expected.empty() && !has(s.expected)) failures.push_back("missing_status:" + s.expected);
  // a fault named where none was injected is a false alarm
  const bool any_fault_named = !r.device_errors.empty() || !r.guard_faults.empty() ||
                               has("invalid_input") || has("numerical_fault");
  if (s.injected == "none" && any_fault_named) failures.push_back("false_alarm");

  if (!failures.empty()) {
    r.outcome = "failed:" + join(failures, "+");
  } else if (s.injected != "none") {
    if (r.detection_tick >= 0) {
      std::string what = !r.guard_faults.empty() ? r.guard_faults.front()
                         : has("invalid_input") ? "invalid_input"
                         : !r.device_errors.empty() ? r.device_errors.front()
                                                    : "fault";
      r.outcome = "fault_detected:" + what;
    } else {
      r.outcome = "fault_undetected:" + s.injected;
    }
  } else if (!r.energy_bounded) {
    r.outcome = "limit_cycle";
  } else {
    r.outcome = "ok";
  }
  return r;
}

}  // namespace vmh::studies

namespace vmh::studies {
namespace {


std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// one scenario's time series: what the observer and the command did
std::string series_csv(const std::vector<TraceRow>& rows) {
  std::string s =
      "t_s,period_s,F_N,tau_1_Nm,tau_2_Nm,tau_3_Nm,energy_motor_J,"
      "energy_hand_J,kinetic_J,d_pivot_mm,status,read,guard\n";
  s.reserve(rows.size() * 160);
  char buf[320];
  for (const TraceRow& r : rows) {
    std::snprintf(buf, sizeof buf,
                  "%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%.9g,%.9g,%.9g,%.6g,%u,%s,%s\n",
                  r.t_s, r.period_s, r.out.force_device_N.norm(),
                  r.motor_torque_Nm[0], r.motor_torque_Nm[1], r.motor_torque_Nm[2],
                  r.energy_motor_J, r.energy_hand_J, r.kinetic_J,
                  r.p_true_mm.norm(), static_cast<unsigned>(r.out.status),
                  device_error_name(r.servo.read), guard_fault_name(r.guard));
    s += buf;
  }
  return s;
}

// XML text: & < > " escaped
std::string xml_text(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

const char* outcome_colour(const std::string& outcome) {
  if (outcome == "ok") return "#2e7d32";
  if (outcome == "limit_cycle") return "#e65100";
  if (outcome.rfind("fault_detected", 0) == 0) return "#1565c0";
  if (outcome.rfind("fault_undetected", 0) == 0) return "#6a1b9a";
  return "#c62828";
}

// One small panel per scenario: the passivity observer E(t) in mJ over the
// whole run, its own vertical scale (min and max labelled), zero dashed, the
// end of the script dashed, the rest window the study judges shaded.
std::string energy_panels_svg(const std::vector<ExtremeResult>& results,
                              const std::vector<std::vector<double>>& t_s,
                              const std::vector<std::vector<double>>& e_J) {
  const int cols = 5, pw = 230, ph = 132, pad = 10, top = 58;
  const int rows = (static_cast<int>(results.size()) + cols - 1) / cols;
  const int W = cols * pw, H = top + rows * ph + 10;
  const int gx = 46, gy = 30, gw = pw - gx - pad, gh = ph - gy - 22;
  std::string s;
  char b[512];
  std::snprintf(b, sizeof b,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"extremes\" "
                "width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
                "font-family=\"sans-serif\">\n<rect width=\"%d\" height=\"%d\" "
                "fill=\"white\"/>\n",
                W, H, W, H, W, H);
  s += b;
  s += "<text x=\"10\" y=\"22\" font-size=\"15\">Extreme cases: the "
       "passivity observer E(t), energy the motors put into the device "
       "(mJ)</text>\n<text x=\"10\" y=\"42\" font-size=\"11\" "
       "fill=\"#555\">t from 0 to the end of the rest; dashed vertical: end "
       "of the script; grey: the window judged (E may rise at most ";
  std::snprintf(b, sizeof b, "%.3g mJ", 1e3 * kRestEnergyRiseBoundJ);
  s += b;
  s += " there); colour: outcome</text>\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const ExtremeResult& r = results[i];
    const int x0 = static_cast<int>(i % cols) * pw, y0 = top + static_cast<int>(i / cols) * ph;
    const std::vector<double>& T = t_s[i];
    const std::vector<double>& E = e_J[i];
    double t_end = r.simulated_s > 0.0 ? r.simulated_s : 1.0;
    double lo = 0.0, hi = 0.0;
    for (double e : E) {
      lo = std::min(lo, 1e3 * e);
      hi = std::max(hi, 1e3 * e);
    }
    if (hi - lo < 1e-6) hi = lo + 1.0;
    auto X = [&](double t) { return x0 + gx + gw * t / t_end; };
    auto Y = [&](double mJ) { return y0 + gy + gh * (hi - mJ) / (hi - lo); };
    std::snprintf(b, sizeof b, "<g class=\"panel\" id=\"panel-%s\">\n",
                  xml_text(r.scenario.name).c_str());
    s += b;
    std::snprintf(b, sizeof b,
                  "<text x=\"%d\" y=\"%d\" font-size=\"11\">%s</text>\n"
                  "<text x=\"%d\" y=\"%d\" font-size=\"10\" fill=\"%s\">%s</text>\n",
                  x0 + 6, y0 + 12, xml_text(r.scenario.name).c_str(), x0 + 6,
                  y0 + 24, outcome_colour(r.outcome), xml_text(r.outcome).c_str());
    s += b;
    const double script_end = t_end - kExtremeRestS;
    std::snprintf(b, sizeof b,
                  "<rect x=\"%.1f\" y=\"%d\" width=\"%.1f\" height=\"%d\" "
                  "fill=\"#e0e0e0\"/>\n<rect x=\"%d\" y=\"%d\" width=\"%d\" "
                  "height=\"%d\" fill=\"none\" stroke=\"#999\"/>\n",
                  X(t_end - kRestWindowS), y0 + gy, X(t_end) - X(t_end - kRestWindowS),
                  gh, x0 + gx, y0 + gy, gw, gh);
    s += b;
    std::snprintf(b, sizeof b,
                  "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" "
                  "stroke=\"#999\" stroke-dasharray=\"3,3\"/>\n"
                  "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" "
                  "stroke=\"#bbb\" stroke-dasharray=\"2,2\"/>\n",
                  X(script_end), y0 + gy, X(script_end), y0 + gy + gh, x0 + gx,
                  Y(0.0), x0 + gx + gw, Y(0.0));
    s += b;
    std::snprintf(b, sizeof b,
                  "<text x=\"%d\" y=\"%d\" font-size=\"9\" text-anchor=\"end\">%.3g</text>\n"
                  "<text x=\"%d\" y=\"%d\" font-size=\"9\" text-anchor=\"end\">%.3g</text>\n"
                  "<text x=\"%d\" y=\"%d\" font-size=\"9\">0</text>\n"
                  "<text x=\"%d\" y=\"%d\" font-size=\"9\" text-anchor=\"end\">%.0f s</text>\n",
                  x0 + gx - 3, y0 + gy + 8, hi, x0 + gx - 3, y0 + gy + gh, lo,
                  x0 + gx, y0 + gy + gh + 11, x0 + gx + gw, y0 + gy + gh + 11, t_end);
    s += b;
    s += "<polyline fill=\"none\" stroke=\"#1565c0\" stroke-width=\"1\" points=\"";
    for (std::size_t k = 0; k < T.size(); ++k) {
      std::snprintf(b, sizeof b, "%.1f,%.1f ", X(T[k]), Y(1e3 * E[k]));
      s += b;
    }
    s += "\"/>\n</g>\n";
  }
  s += "</svg>\n";
  return s;
}

}  // namespace

nlohmann::json extreme_result_json(const ExtremeResult& r) {
  const ExtremeScenario& s = r.scenario;
  auto v3 = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  return {
      {"name", s.name},
      {"base", s.base},
      {"overrides", s.overrides},
      {"stresses", s.stresses},
      {"injected_fault", s.injected},
      {"expected_status", s.expected},
      {"outcome", r.outcome},
      {"pass", r.pass()},
      {"simulated_s", r.simulated_s},
      {"ticks", r.ticks},
      {"wall_time_s", r.wall_time_s},
      {"finite", r.finite},
      {"first_nonfinite", r.first_nonfinite},
      {"nonfinite_reading_ticks", r.nonfinite_reading_ticks},
      {"force_limit_N", r.force_limit_N},
      {"max_force_N", r.max_force_N},
      {"motor_limit_Nm", v3(r.motor_limit_Nm)},
      {"max_motor_torque_Nm", v3(r.max_motor_torque_Nm)},
      {"force_within_limit", r.force_within_limit},
      {"torque_within_limit", r.torque_within_limit},
      {"energy",
       {{"motor_max_J", r.energy_motor_max_J},
        {"motor_min_J", r.energy_motor_min_J},
        {"motor_final_J", r.energy_motor_final_J},
        {"hand_final_J", r.energy_hand_final_J},
        {"kinetic_max_J", r.kinetic_max_J},
        {"rest_rise_J", r.rest_energy_rise_J},
        {"rest_rise_bound_J", kRestEnergyRiseBoundJ},
        {"rest_kinetic_max_J", r.rest_kinetic_max_J},
        {"bounded", r.energy_bounded},
        {"passive", r.passive},
        {"passive_tolerance_J", kPassiveToleranceJ},
        {"expected", r.energy_expected},
        {"expected_why", s.energy_why}}},
      {"colgate",
       {{"demand_Ns_per_m", r.colgate_demand_Ns_per_m},
        {"b_Ns_per_m", r.colgate_b_Ns_per_m},
        {"passive", r.colgate_passive}}},
      {"statuses", r.statuses},
      {"device_errors", r.device_errors},
      {"guard_faults", r.guard_faults},
      {"zeroed_ticks", r.zeroed_ticks},
      {"mujoco_warnings", r.mujoco_warnings},
      {"fault_tick", r.fault_tick},
      {"detection_tick", r.detection_tick},
      {"detection_latency_ticks",
       r.fault_tick >= 0 && r.detection_tick >= 0 ? r.detection_tick - r.fault_tick : -1},
      {"max_torque_after_detection_Nm", r.max_torque_after_detection_Nm},
      {"reached",
       {{"min_pivot_distance_mm", r.min_pivot_distance_mm},
        {"orientation_wraps", r.orientation_wraps},
        {"min_q5_to_singular_rad", r.min_q5_to_singular_rad},
        {"min_pole_angle_rad", r.min_pole_angle_rad},
        {"max_reach_fraction", r.max_reach_fraction},
        {"max_encoder_speed_rad_s", r.max_encoder_speed_rad_s},
        {"min_period_s", r.min_period_s},
        {"max_period_s", r.max_period_s},
        {"mean_period_s", r.mean_period_s}}},
  };
}

std::string extremes_csv(const std::vector<ExtremeResult>& results) {
  std::string s =
      "name,base,injected_fault,expected_status,outcome,finite,max_force_N,"
      "force_limit_N,max_tau_1_Nm,max_tau_2_Nm,max_tau_3_Nm,"
      "energy_motor_max_J,energy_motor_min_J,energy_motor_final_J,"
      "rest_energy_rise_J,energy_hand_final_J,kinetic_max_J,"
      "rest_kinetic_max_J,energy_bounded,passive,energy_expected,"
      "colgate_demand_Ns_per_m,colgate_b_Ns_per_m,statuses,device_errors,guard_faults,zeroed_ticks,"
      "mujoco_warnings,detection_latency_ticks,min_pivot_distance_mm,"
      "min_pole_angle_rad,orientation_wraps,min_q5_to_singular_rad,"
      "max_reach_fraction,max_encoder_speed_rad_s,min_period_s,max_period_s,"
      "simulated_s,ticks,wall_time_s\n";
  char buf[640];
  for (const ExtremeResult& r : results) {
    s += csv_field(r.scenario.name) + "," + r.scenario.base + "," +
         r.scenario.injected + "," + r.scenario.expected + "," +
         csv_field(r.outcome) + "," + (r.finite ? "1" : "0") + ",";
    std::snprintf(buf, sizeof buf,
                  "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,"
                  "%.6g,%d,%d,",
                  r.max_force_N, r.force_limit_N, r.max_motor_torque_Nm[0],
                  r.max_motor_torque_Nm[1], r.max_motor_torque_Nm[2],
                  r.energy_motor_max_J, r.energy_motor_min_J,
                  r.energy_motor_final_J, r.rest_energy_rise_J,
                  r.energy_hand_final_J, r.kinetic_max_J, r.rest_kinetic_max_J,
                  r.energy_bounded ? 1 : 0, r.passive ? 1 : 0);
    s += buf;
    s += r.energy_expected + ",";
    std::snprintf(buf, sizeof buf, "%.6g,%.6g,", r.colgate_demand_Ns_per_m,
                  r.colgate_b_Ns_per_m);
    s += buf;
    s += csv_field(join(r.statuses, " ")) + "," +
         csv_field(join(r.device_errors, " ")) + "," +
         csv_field(join(r.guard_faults, " ")) + ",";
    std::snprintf(buf, sizeof buf,
                  "%d,%d,%d,%.6g,%.6g,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.6g\n",
                  r.zeroed_ticks, r.mujoco_warnings,
                  r.fault_tick >= 0 && r.detection_tick >= 0
                      ? r.detection_tick - r.fault_tick
                      : -1,
                  r.min_pivot_distance_mm, r.min_pole_angle_rad,
                  r.orientation_wraps, r.min_q5_to_singular_rad,
                  r.max_reach_fraction, r.max_encoder_speed_rad_s,
                  r.min_period_s, r.max_period_s, r.simulated_s, r.ticks,
                  r.wall_time_s);
    s += buf;
  }
  return s;
}

nlohmann::json run_extremes_study(const std::vector<std::string>& only,
                                  const std::string& out_dir, int jobs,
                                  std::vector<ExtremeResult>* results) {
  std::vector<ExtremeScenario> table = extreme_scenarios();
  if (!only.empty()) {
    std::vector<ExtremeScenario> picked;
    for (const std::string& n : only) {
      auto it = std::find_if(table.begin(), table.end(),
                             [&n](const ExtremeScenario& s) { return s.name == n; });
      if (it == table.end()) {
        std::string names;
        for (const ExtremeScenario& s : table) names += (names.empty() ? "" : ", ") + s.name;
        throw SimError("unknown extreme scenario '" + n + "' (known: " + names + ")");
      }
      picked.push_back(*it);
    }
    table = picked;
  }
  if (!out_dir.empty()) {
    std::error_code ec;
    fs::create_directories(fs::path(out_dir) / "extremes", ec);
    if (ec) throw SimError(out_dir + ": " + ec.message());
  }
  // the scenarios are independent: run them on `jobs` threads (ClosedLoop
  // finds its hand through a thread-local pointer, and model loading is
  // serialised), each keeping its time series only as long as it needs it
  results->assign(table.size(), ExtremeResult{});
  std::vector<std::vector<double>> energy_t(table.size()), energy_J(table.size());
  std::vector<std::string> errors(table.size());
  const auto start = std::chrono::steady_clock::now();
  report::parallel_for(table.size(), jobs, [&](std::size_t i) {
    std::vector<TraceRow> rows;
    try {
      (*results)[i] = run_extreme(table[i], &rows);
      // the observer, thinned for the figure to about 400 buckets, each
      // drawn by its lowest and highest point in time order, so that no
      // peak or dip is lost to the thinning (the table's max and min are
      // the curve's)
      const std::size_t stride = std::max<std::size_t>(1, rows.size() / 400);
      for (std::size_t k0 = 0; k0 < rows.size(); k0 += stride) {
        const std::size_t k1 = std::min(rows.size(), k0 + stride);
        std::size_t lo = k0, hi = k0;
        for (std::size_t k = k0; k < k1; ++k) {
          if (rows[k].energy_motor_J < rows[lo].energy_motor_J) lo = k;
          if (rows[k].energy_motor_J > rows[hi].energy_motor_J) hi = k;
        }
        for (std::size_t k : {std::min(lo, hi), std::max(lo, hi)}) {
          if (k == std::max(lo, hi) && lo == hi) break;
          energy_t[i].push_back(rows[k].t_s);
          energy_J[i].push_back(rows[k].energy_motor_J);
        }
      }
      if (!out_dir.empty()) {
        report::write_file_atomically(
            (fs::path(out_dir) / "extremes" / (table[i].name + ".csv")).string(),
            series_csv(rows));
      }
    } catch (const std::exception& e) {
      errors[i] = table[i].name + ": " + e.what();
    }
  });
  for (const std::string& e : errors) {
    if (!e.empty()) throw SimError(e);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  nlohmann::json scenarios = nlohmann::json::array();
  bool all_pass = true;
  for (const ExtremeResult& r : *results) {
    scenarios.push_back(extreme_result_json(r));
    all_pass &= r.pass();
  }
  nlohmann::json j = {
      {"study", "extremes"},
      {"duration_s", kExtremeDurationS},
      {"rest_s", kExtremeRestS},
      {"bounds",
       {{"rest_s", kExtremeRestS},
        {"rest_window_s", kRestWindowS},
        {"rest_energy_rise_bound_J", kRestEnergyRiseBoundJ},
        {"passive_tolerance_J", kPassiveToleranceJ}}},
      {"scenarios", scenarios},
      {"all_pass", all_pass},
      {"wall_time_s", wall},
  };
  if (!out_dir.empty()) {
    report::write_file_atomically((fs::path(out_dir) / "extremes.csv").string(), extremes_csv(*results));
    report::write_file_atomically((fs::path(out_dir) / "extremes.json").string(), j.dump(2) + "\n");
    report::write_file_atomically((fs::path(out_dir) / "extremes.svg").string(),
energy_panels_svg(*results, energy_t, energy_J));
  }
  return j;
}

}  // namespace vmh::studies
