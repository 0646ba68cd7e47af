#include "studies/extremes_study.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "output/output_file.h"
#include "output/parallel.h"
#include "studies/run_case.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace fs = std::filesystem;
namespace {

using constants::kPi;

std::string vec_text(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g", v.x(), v.y(), v.z());
  return buf;
}

// The start point of the circle cases (pivot at the origin, L = 50 mm, the
// default script_dir projected on the device x-y plane), and the forearm's
// direction there (z4 of Table B.1: elbow to wrist centre, device frame) on
// the IK branch nearest the home pose. With q5 = +pi/2 the stylus axis z6 is
// -z4: the pen continues the forearm, tip away from the elbow.
Vec3 circle_start_mm() {
  // the table's defaults, typed: a circle scene that sets nothing else
  const sim::CaseParams defaults = sim::load_case_params(
      "the case table's defaults",
      {{"vm_kind", "circle", sim::ValueSource::kScene, "defaults"}});
  Vec3 dir = defaults.script.dir;
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
const char* nonfinite_part(const TickRecord& r) {
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


namespace {

// The force limit and the motors' torque clamps (ctrlrange of m1..m3).
void read_limits(const ClosedLoop& loop, ExtremeResult* r) {
  const mjModel* m = loop.model();
  r->force_limit_N = loop.controller_params().force_limit_N;
  for (int i = 0; i < 3; ++i) {
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, ("m" + std::to_string(i + 1)).c_str());
    r->motor_limit_Nm[i] = m->actuator_ctrlrange[2 * a + 1];
  }
}

// Ticks the loop until end_s, a row per tick; the wall time and the ticks
// go in r.
void run_ticks(ClosedLoop* loop, double end_s, std::vector<TickRecord>* rows,
               ExtremeResult* r, const StopFn& stop) {
  const mjModel* m = loop->model();
  rows->clear();
  rows->reserve(static_cast<std::size_t>(loop->ticks_per_run()));
  const auto start = std::chrono::steady_clock::now();
  while (loop->time_s() < end_s - 0.5 * m->opt.timestep) {
    throw_if_stop_asked(stop);
    rows->emplace_back();
    loop->tick(&rows->back());
  }
  r->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r->simulated_s = loop->time_s();
  r->ticks = static_cast<int>(rows->size());
}

// What every tick adds to the result: the four counts' raw material, and
// what the scenario reached.
class TickScan {
 public:
  TickScan(const ClosedLoop& loop, double end_s, ExtremeResult* r)
      : params_(loop.controller_params()),
        r_(r),
        shoulder_mm_(base_to_device_mm(params_.omni, Vec3::Zero())),
        reach_mm_(1000.0 * (params_.omni.l1_m + params_.omni.l2_m)),
        window_from_s_(end_s - kRestWindowS),
        pole_axis_(params_.vm.R_pivot.col(2)) {
    r_->energy_motor_max_J = r_->energy_motor_min_J = 0.0;
    r_->min_pivot_distance_mm = 1e300;
    r_->min_q5_to_singular_rad = 1e300;
    r_->min_period_s = 1e300;
    r_->min_pole_angle_rad = 1e300;
  }

  void add(const std::vector<TickRecord>& rows, std::size_t k) {
    const TickRecord& row = rows[k];
    finite(row);
    command(row);
    statuses(row, static_cast<int>(k));
    energy(row);
    reached(row, k > 0 ? &rows[k - 1] : nullptr);
  }

  // the mean period, and the names seen, sorted
  void finish(std::size_t ticks) {
    r_->mean_period_s = ticks == 0 ? 0.0 : period_sum_ / static_cast<double>(ticks);
    for (int b = 0; b < kStatusFlagCount; ++b) {
      if (seen_ & (1u << b)) statuses_.insert(status_flag_name(1u << b));
    }
    r_->statuses.assign(statuses_.begin(), statuses_.end());
    r_->device_errors.assign(device_errors_.begin(), device_errors_.end());
    r_->guard_faults.assign(guard_faults_.begin(), guard_faults_.end());
  }

  // whether the rest's last window was reached
  bool in_window() const { return in_window_; }

 private:
  void finite(const TickRecord& row) {
    if (r_->finite) {
      if (const char* part = nonfinite_part(row)) {
        r_->finite = false;
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s at t = %.4f s", part, row.t_s);
        r_->first_nonfinite = buf;
      }
    }
    if (!row.q_dh.allFinite()) ++r_->nonfinite_reading_ticks;
  }

  // the command as the controller computed it and as the motors held it
  void command(const TickRecord& row) {
    r_->max_force_N = std::max(r_->max_force_N, row.out.force_device_N.norm());
    for (int i = 0; i < 3; ++i) {
      r_->max_motor_torque_Nm[i] =
          std::max(r_->max_motor_torque_Nm[i], std::abs(row.motor_torque_Nm[i]));
    }
  }

  void statuses(const TickRecord& row, int tick) {
    if (row.servo.read == DeviceError::kOk) seen_ |= row.out.status;
    if (row.servo.read != DeviceError::kOk) device_errors_.insert(device_error_name(row.servo.read));
    if (row.servo.write != DeviceError::kOk) device_errors_.insert(device_error_name(row.servo.write));
    if (row.guard != GuardFault::kNone) guard_faults_.insert(guard_fault_name(row.guard));
    if (row.servo.zeroed) ++r_->zeroed_ticks;
    const bool fault_named = row.servo.read != DeviceError::kOk ||
                             (row.servo.read == DeviceError::kOk && is_fault(row.out.status));
    if (row.fault_injected && r_->fault_tick < 0) r_->fault_tick = tick;
    if (r_->fault_tick >= 0 && r_->detection_tick < 0 && fault_named) r_->detection_tick = tick;
    if (r_->detection_tick >= 0 && tick >= r_->detection_tick) {
      r_->max_torque_after_detection_Nm =
          std::max(r_->max_torque_after_detection_Nm, row.motor_torque_Nm.cwiseAbs().maxCoeff());
    }
  }

  void energy(const TickRecord& row) {
    const double E = row.energy_motor_J;
    r_->energy_motor_max_J = std::max(r_->energy_motor_max_J, E);
    r_->energy_motor_min_J = std::min(r_->energy_motor_min_J, E);
    r_->kinetic_max_J = std::max(r_->kinetic_max_J, row.kinetic_J);
    if (row.t_s >= window_from_s_) {
      if (!in_window_) {
        in_window_ = true;
        window_start_J_ = prev_end_J_;
      }
      r_->rest_energy_rise_J = std::max(r_->rest_energy_rise_J, E - window_start_J_);
      r_->rest_kinetic_max_J = std::max(r_->rest_kinetic_max_J, row.kinetic_J);
    }
    prev_end_J_ = E;
    r_->energy_motor_final_J = E;
    r_->energy_hand_final_J = row.energy_hand_J;
  }

  // what the scenario reached, from MuJoCo's true angles
  void reached(const TickRecord& row, const TickRecord* prev) {
    const Vec3 from_pivot = row.p_true_mm - params_.vm.pivot_mm;
    r_->min_pivot_distance_mm = std::min(r_->min_pivot_distance_mm, from_pivot.norm());
    if (from_pivot.norm() > 1e-9) {
      const double c = std::abs(from_pivot.normalized().dot(pole_axis_));
      r_->min_pole_angle_rad = std::min(r_->min_pole_angle_rad, std::acos(std::min(1.0, c)));
    }
    r_->max_reach_fraction =
        std::max(r_->max_reach_fraction, (row.p_true_mm - shoulder_mm_).norm() / reach_mm_);
    r_->min_q5_to_singular_rad = std::min(
        r_->min_q5_to_singular_rad, std::abs(0.5 * kPi - std::abs(wrap_angle(row.q_true_dh[4]))));
    if (prev != nullptr) {
      // encoder speeds over the previous tick, device joints t1..t3
      const Joints dq = dh_to_device_joints(row.q_true_dh) - dh_to_device_joints(prev->q_true_dh);
      r_->max_encoder_speed_rad_s = std::max(
          r_->max_encoder_speed_rad_s, dq.head<3>().cwiseAbs().maxCoeff() / prev->period_s);
      const Vec6 de = row.out.e - prev->out.e;
      for (int i = 3; i < 6; ++i) {
        if (std::abs(de[i]) > kPi) {
          ++r_->orientation_wraps;
          break;
        }
      }
    }
    r_->min_period_s = std::min(r_->min_period_s, row.period_s);
    r_->max_period_s = std::max(r_->max_period_s, row.period_s);
    period_sum_ += row.period_s;
  }

  const ControllerParams& params_;
  ExtremeResult* r_;
  const Vec3 shoulder_mm_;
  const double reach_mm_;
  const double window_from_s_;  // the rest's last window starts here
  const Vec3 pole_axis_;
  std::set<std::string> statuses_, device_errors_, guard_faults_;
  ControlStatus seen_ = kStatusOk;
  double period_sum_ = 0.0;
  bool in_window_ = false;
  double window_start_J_ = 0.0;
  double prev_end_J_ = 0.0;  // the observer at the end of the last tick
};

// The limits, the energy (the observer, and Colgate & Schenkel's bound for
// this scenario's translational gains) and what it is expected to do.
void judge(const ClosedLoop& loop, bool in_window, ExtremeResult* r) {
  r->force_within_limit = r->max_force_N <= r->force_limit_N * (1.0 + 1e-12);
  r->torque_within_limit = true;
  for (int i = 0; i < 3; ++i) {
    r->torque_within_limit &= r->max_motor_torque_Nm[i] <= r->motor_limit_Nm[i] * (1.0 + 1e-12);
  }
  r->passive = r->energy_motor_max_J <= kPassiveToleranceJ;
  r->energy_bounded = in_window && r->rest_energy_rise_J <= kRestEnergyRiseBoundJ;

  // Colgate & Schenkel's bound for this scenario's translational gains
  const CaseConfig& c = loop.config();
  const double T_max_s = loop.substeps_max() * loop.model()->opt.timestep;
  r->colgate_demand_Ns_per_m = 1000.0 * c.controller.k_pos_N_per_mm * T_max_s / 2.0 +
                              1000.0 * std::abs(c.controller.k_vel_Ns_per_mm);
  // an anisotropic hand: its least damped axis
  r->colgate_b_Ns_per_m = c.hand.b_pos_axes_Ns_per_m.isZero(0.0)
                              ? c.hand.b_pos_Ns_per_m
                              : c.hand.b_pos_axes_Ns_per_m.minCoeff();
  r->colgate_passive = r->colgate_b_Ns_per_m > r->colgate_demand_Ns_per_m;
  r->energy_expected = r->scenario.energy;
  if (r->energy_expected == "bounded" && !r->colgate_passive) r->energy_expected = "either";
}

// ok, limit_cycle, fault_detected:<name>, fault_undetected:<fault> or
// failed:<reasons> (ExtremeResult::outcome)
std::string outcome_of(const ExtremeResult& r) {
  const ExtremeScenario& s = r.scenario;
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

  if (!failures.empty()) return "failed:" + join(failures, "+");
  if (s.injected != "none") {
    if (r.detection_tick < 0) return "fault_undetected:" + s.injected;
    const std::string what = !r.guard_faults.empty() ? r.guard_faults.front()
                             : has("invalid_input") ? "invalid_input"
                             : !r.device_errors.empty() ? r.device_errors.front()
                                                        : "fault";
    return "fault_detected:" + what;
  }
  return r.energy_bounded ? "ok" : "limit_cycle";
}

// the table, or the scenarios named in `only` in that order; SimError for
// an unknown name, listing the known ones
std::vector<ExtremeScenario> pick_scenarios(const std::vector<std::string>& only) {
  const std::vector<ExtremeScenario> table = extreme_scenarios();
  if (only.empty()) return table;
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
  return picked;
}

}  // namespace

ExtremeResult run_extreme(const ExtremeScenario& s,
                          std::vector<TickRecord>* trace, const StopFn& stop) {
  ExtremeResult r;
  r.scenario = s;
  std::string name;
  const std::string scene = sim::resolve_scene(s.base, &name);
  std::vector<std::string> sets = {
      "duration_s=" + std::to_string(kExtremeDurationS),
      std::string("integrator=") + kExtremeIntegrator};
  sets.insert(sets.end(), s.overrides.begin(), s.overrides.end());
  ClosedLoop loop(scene, sets);
  read_limits(loop, &r);
  const double script_end_s = loop.config().sim.duration_s;
  const double end_s = script_end_s + kExtremeRestS;

  std::vector<TickRecord> local;
  std::vector<TickRecord>& rows = trace != nullptr ? *trace : local;
  run_ticks(&loop, end_s, &rows, &r, stop);

  TickScan scan(loop, end_s, &r);
  for (std::size_t k = 0; k < rows.size(); ++k) scan.add(rows, k);
  scan.finish(rows.size());
  for (int i = 0; i < mjNWARNING; ++i) r.mujoco_warnings += loop.data()->warning[i].number;

  judge(loop, scan.in_window(), &r);
  r.outcome = outcome_of(r);
  return r;
}

ExtremesResult run_extremes_study(const ExtremesOptions& o) {
  const std::vector<ExtremeScenario> table = pick_scenarios(o.only);
  // the series' set (out_dir/extremes, made beside it and put in place at
  // the end); out_dir itself, if this run makes it, is removed again (if
  // still empty) when the study stops or fails before writing
  struct RemoveIfMadeHere {
    std::string dir;
    bool keep = false;
    ~RemoveIfMadeHere() {
      std::error_code ignored;
      if (!keep && !dir.empty()) fs::remove(dir, ignored);  // only if empty
    }
  } made_here;
  std::unique_ptr<output::OutputSet> series;
  if (!o.out_dir.empty()) {
    std::error_code ec;
    if (!fs::exists(o.out_dir, ec)) made_here.dir = o.out_dir;
    try {
      series = std::make_unique<output::OutputSet>(
          (fs::path(o.out_dir) / "extremes").string());
    } catch (const std::runtime_error& e) {
      throw SimError(o.out_dir + ": " + e.what());
    }
  }
  // the scenarios are independent: run them on `jobs` threads (each loop's
  // hand is registered for its own mjData, and model loading is
  // serialised), each keeping its time series only as long as it needs it
  ExtremesResult result;
  result.scenarios.assign(table.size(), ExtremeResult{});
  result.energy.assign(table.size(), EnergyCurve{});
  std::vector<std::string> errors(table.size());
  const auto start = std::chrono::steady_clock::now();
  std::atomic<std::size_t> finished{0};
  std::atomic<bool> stopped{false};
  output::parallel_for(table.size(), o.jobs, [&](std::size_t i) {
    // once stopped, the scenarios not begun are skipped
    if (stopped || stop_asked(o.should_stop)) {
      stopped = true;
      return;
    }
    std::vector<TickRecord> rows;
    try {
      result.scenarios[i] = run_extreme(table[i], &rows, o.should_stop);
      result.energy[i] = thin_energy(rows);
      if (series) series->write(table[i].name + ".csv", extreme_series_csv(rows));
    } catch (const Interrupted&) {
      stopped = true;
      return;
    } catch (const std::exception& e) {
      errors[i] = table[i].name + ": " + e.what();
    }
    if (o.progress) o.progress(++finished, table.size());
  });
  if (stopped) throw Interrupted();
  for (const std::string& e : errors) {
    if (!e.empty()) throw SimError(e);
  }
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // the last poll: from here the series' folder and the three files go in
  throw_if_stop_asked(o.should_stop);
  if (series) {
    made_here.keep = true;
    series->commit();
    write_extremes_files(result, o.out_dir);
  }
  return result;
}

bool ExtremesResult::all_pass() const {
  return std::all_of(scenarios.begin(), scenarios.end(),
                     [](const ExtremeResult& r) { return r.pass(); });
}

}  // namespace vmh::studies
