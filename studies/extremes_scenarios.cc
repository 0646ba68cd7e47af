// The extreme scenarios (extreme_scenarios(), studies/extremes_study.h): a
// table, each row a case, its overrides, what it tries and what it may
// touch, with the poses that need the Omni's geometry worked out here.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "studies/extremes_study.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

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

}  // namespace vmh::studies
