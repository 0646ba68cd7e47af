#include "sim/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/cases/case_params_detail.h"

namespace vmh::sim {
namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

using constants::kPi;

// splitmix64 (Steele, Lea & Flood, OOPSLA 2014): a fixed, portable sequence,
// so that a jitter_seed means the same run with any standard library
std::uint64_t next_random(std::uint64_t* state) {
  std::uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// a number in a message: %g-style, 9 significant digits (1e-07, 0.001)
std::string num(double v) { return detail::format_number(v); }

// the stylus rotation (DH base frame) whose z axis is `axis_base`, reached
// from `R_ref` by the smallest rotation
Mat3 turn_to_axis(const Mat3& R_ref, const Vec3& axis_base) {
  const Eigen::Quaterniond q =
      Eigen::Quaterniond::FromTwoVectors(R_ref.col(2), axis_base);
  return q.toRotationMatrix() * R_ref;
}

ModelPtr copy_model(const mjModel& m, const std::string& path) {
  ModelPtr copy(mj_copyModel(nullptr, &m));
  if (!copy) throw SimError(path + ": mj_copyModel failed");
  return copy;
}

}  // namespace

ModelPtr load_scene_model(const std::string& path, const ModelHook& hook,
                          bool headless) {
  ModelPtr m = headless ? load_model_headless(path) : load_model(path);
  if (hook) hook(m.get());
  return m;
}

ClosedLoop::ClosedLoop(const std::string& scene_path,
                       const std::vector<std::string>& overrides,
                       const ModelHook& model_hook)
    : path_(scene_path),
      plant_(load_scene_model(scene_path, model_hook), scene_path),
      case_(make_case(scene_path, *plant_.model(), overrides)) {
  init();
}

ClosedLoop::ClosedLoop(const std::string& scene_path, const mjModel& compiled,
                       const std::vector<std::string>& overrides)
    : path_(scene_path),
      plant_(copy_model(compiled, scene_path), scene_path),
      case_(make_case(scene_path, *plant_.model(), overrides)) {
  init();
}

ClosedLoop::ClosedLoop(const Case& c, const ModelHook& model_hook)
    : path_(c.scene_path()),
      plant_(load_scene_model(c.scene_path(), model_hook), c.scene_path()),
      case_(c) {
  init();
}

void ClosedLoop::init() {
  apply_model_options();
  plant_.make_data();
  hand_ = std::make_unique<SimHand>(plant_.mutable_model(), plant_.data(),
                                    hand_params(case_.config()), path_);
  {
    // the grip site's offset and rotation in the stylus body, fixed
    const int g = hand_->grip_site();
    grip_local_ = Vec3(plant_.model()->site_pos + 3 * g);
    mju_quat2Mat(R_site_.data(), plant_.model()->site_quat + 4 * g);
  }
  build_controller();
  build_device_chain();
  q_start_dh_ = start_pose();
  reset();
}

void ClosedLoop::apply_model_options() {
  mjModel* m = plant_.mutable_model();
  const SimSettings& sim = case_.config().sim;
  if (sim.physics_step_s > 0.0) m->opt.timestep = sim.physics_step_s;
  switch (sim.integrator) {
    case IntegratorSetting::kScene: break;
    case IntegratorSetting::kEuler: m->opt.integrator = mjINT_EULER; break;
    case IntegratorSetting::kImplicit: m->opt.integrator = mjINT_IMPLICIT; break;
    case IntegratorSetting::kRk4: m->opt.integrator = mjINT_RK4; break;
  }
}

void ClosedLoop::build_controller() {
  mjModel* m = plant_.mutable_model();
  const ControllerParams& params = case_.controller_params();
  // the case's controller has the gimbal's ranges opened without its limits
  if (!case_.config().sim.gimbal_limits) {
    // the wrist free to turn through its singularity: no limits on q4..q6
    // in the model either
    for (int i = 3; i < 6; ++i) {
      const std::string name = "q" + std::to_string(i + 1);
      m->jnt_limited[require_id(m, mjOBJ_JOINT, name.c_str(), path_)] = 0;
    }
  }
  // the motors' range follows the case's torque limits (torque_limits):
  // omni.xml's ctrlrange is the OpenHaptics samples' clamps, which would
  // otherwise cut the rated limits' torques in the simulated motors
  for (int i = 0; i < kOmniActuated; ++i) {
    const std::string name = "m" + std::to_string(i + 1);
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, name.c_str());
    if (a < 0 || !m->actuator_ctrllimited[a]) continue;
    const double lim = params.omni.motor_torque_limit_Nm[static_cast<std::size_t>(i)];
    m->actuator_ctrlrange[2 * a] = -lim;
    m->actuator_ctrlrange[2 * a + 1] = lim;
    if (m->actuator_forcelimited[a]) {
      m->actuator_forcerange[2 * a] = -lim;
      m->actuator_forcerange[2 * a + 1] = lim;
    }
  }
}

void ClosedLoop::build_device_chain() {
  const SimSettings& sim = case_.config().sim;
  device_ = std::make_unique<SimDevice>(plant_.mutable_model(), plant_.data(),
                                        case_.controller_params().omni, sim.quantize,
                                        sim.delay_ticks, path_);
  FaultSpec fault;
  fault.kind = sim.fault;
  fault.joint = sim.fault_joint - 1;
  fault.at_s = sim.fault_at_s;
  fault.jump_rad = kJumpCounts * 2.0 * kPi / case_.controller_params().omni.encoder_counts_per_rev;
  injector_ = std::make_unique<FaultInjector>(device_.get(), fault);
  ChainOptions chain;
  chain.mode = ChainMode::kRun;
  chain.guard.enabled = sim.sensor_guard;
  chain.guard.max_speed_rad_s = sim.guard_max_speed_rad_s;
  chain.guard.max_period_s = case_.substeps_max() * plant_.model()->opt.timestep;
  chain.controller = case_.controller_params();
  chain.safety = sim.safety_layer;
  chain.safety_params = safety_params_for(case_.controller_params());
  try {
    chain_ = std::make_unique<ServoChain>(injector_.get(), chain);
  } catch (const std::invalid_argument& e) {
    throw SimError(path_ + ": " + e.what());
  }
}

Joints ClosedLoop::start_pose() {
  // the script's first target, the stylus turned the least from its home
  // frame; the IK solution nearest the home pose
  const OmniParams& omni = case_.controller_params().omni;
  const ScriptPose start = case_.script().at(0.0);
  const Mat3 R_home = omni_fk(omni, Joints::Zero()).R_base;
  R_start_base_ = turn_to_axis(R_home, device_to_base_vector(start.axis));
  const Vec3 p_base = device_mm_to_base(omni, start.p_mm);
  const IkSolutions ik = omni_ik_pose(omni, p_base, R_start_base_, Joints::Zero());
  int best = -1;
  double best_d = 0.0;
  for (int i = 0; i < ik.count; ++i) {
    if (!ik.within_limits[static_cast<std::size_t>(i)]) continue;
    const double dist = ik.q_dh[static_cast<std::size_t>(i)].squaredNorm();
    if (best < 0 || dist < best_d) {
      best = i;
      best_d = dist;
    }
  }
  if (best < 0) {
    throw SimError(path_ + ": the script's start pose (" +
                   num(start.p_mm.x()) + ", " + num(start.p_mm.y()) + ", " +
                   num(start.p_mm.z()) +
                   ") mm cannot be reached within the joint ranges; change "
                   "script_dir, vm_pivot_mm or vm_length_mm");
  }
  return ik.q_dh[static_cast<std::size_t>(best)];
}

ClosedLoop::~ClosedLoop() = default;

void ClosedLoop::set_reference(const ControllerParams& params) {
  chain_->set_reference(params);
}

double ClosedLoop::time_s() const {
  if (case_.jitter()) return static_cast<double>(substep_count_) * plant_.model()->opt.timestep;
  return static_cast<double>(tick_count_) * case_.controller_params().servo_period_s;
}

bool ClosedLoop::finished() const {
  return script_time_s() >= case_.config().sim.duration_s - 0.5 * plant_.model()->opt.timestep;
}

void ClosedLoop::skip_script_to(double t_s) {
  const double now_s = script_time_s();
  if (!(t_s >= now_s && t_s <= case_.config().sim.duration_s)) {
    throw std::invalid_argument(
        path_ + ": the script's clock can move forward only, within its " +
        num(case_.config().sim.duration_s) + " s: asked " + num(t_s) + " s at " + num(now_s) +
        " s");
  }
  script_skipped_s_ += t_s - now_s;
}

int ClosedLoop::draw_substeps() {
  if (!case_.jitter()) return case_.substeps();
  const auto span = static_cast<std::uint64_t>(case_.substeps_max() -
                                               case_.substeps_min() + 1);
  return case_.substeps_min() +
         static_cast<int>(next_random(&rng_state_) % span);
}

void ClosedLoop::reset() {
  const mjModel* m = plant_.model();
  mjData* d = plant_.data();
  plant_.reset();
  device_->reset();
  injector_->reset();
  chain_->reset();
  tick_count_ = 0;
  substep_count_ = 0;
  script_skipped_s_ = 0.0;
  rng_state_ = case_.config().sim.jitter_seed;
  // write the start angles through the joint addresses
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    d->qpos[m->jnt_qposadr[j]] = q_start_dh_[i];
  }
  set_hand_target(0.0);
  manual_target_ = hand_->target();
  mj_forward(m, d);
}

void ClosedLoop::set_manual_hand(bool on) {
  if (on && !manual_hand_) {
    manual_target_ = hand_->target();
    manual_target_.v_m_s.setZero();
    manual_target_.w_rad_s.setZero();
  }
  manual_hand_ = on;
}

void ClosedLoop::set_manual_target(const HandTargetState& target) {
  manual_target_ = target;
}

ScriptPose ClosedLoop::wrist_pose_of(const HandTargetState& grip) const {
  // undo set_hand_target's grip = wrist + R grip_local, R_grip = R R_site
  const Mat3 R = grip.R * R_site_.transpose();
  ScriptPose pose;
  pose.p_mm = base_to_device_mm(case_.controller_params().omni, grip.p_m - R * grip_local_);
  pose.axis = base_to_device_vector(R.col(2));
  return pose;
}

void ClosedLoop::set_hand_target(double t_s) { (void)script_target(t_s); }

const Mat3& ClosedLoop::stylus_turned_to(const Vec3& axis_base) {
  // the script's axis changes only in its moving and blending stretches,
  // and the two evaluations per tick (t and t + dt) alternate: two entries
  // spare turn_to_axis() wherever the axis is held
  for (TurnMemo& e : turn_memo_) {
    if (e.valid && std::memcmp(e.axis_base.data(), axis_base.data(),
                               3 * sizeof(double)) == 0) {
      return e.R;
    }
  }
  TurnMemo& e = turn_memo_[turn_memo_next_];
  turn_memo_next_ = 1 - turn_memo_next_;
  e.axis_base = axis_base;
  e.R = turn_to_axis(R_start_base_, axis_base);
  e.valid = true;
  return e.R;
}

ScriptPose ClosedLoop::script_target(double t_s) {
  const OmniParams& omni = case_.controller_params().omni;
  auto target_at = [&](double t, Vec3* p_grip, Mat3* R_grip) {
    const ScriptPose pose = case_.script().at(t);
    const Mat3& R = stylus_turned_to(device_to_base_vector(pose.axis));
    // the stylus body's origin is the wrist centre
    const Vec3 wrist = device_mm_to_base(omni, pose.p_mm);
    *p_grip = wrist + R * grip_local_;
    *R_grip = R * R_site_;
    return pose;
  };
  HandTargetState target;
  // past the script's end the hand holds its last target still
  const double t_end_s = case_.config().sim.duration_s;
  const ScriptPose pose =
      target_at(std::min(t_s, t_end_s), &target.p_m, &target.R);
  // the target's velocity by a forward difference over a small interval
  const double dt = 1e-5;
  Vec3 p2;
  Mat3 R2;
  target_at(std::min(t_s + dt, t_end_s), &p2, &R2);
  target.v_m_s = (p2 - target.p_m) / dt;
  const Eigen::AngleAxisd dR(R2 * target.R.transpose());
  target.w_rad_s = dR.angle() * dR.axis() / dt;
  hand_->set_target(plant_.mutable_model(), plant_.data(), target);
  return pose;
}

// the mechanism works in the controller's length unit
double ClosedLoop::distance_to_path_mm(const Vec3& p_mm) const {
  const double u = case_.controller_params().length_unit_mm;
  return controller().mechanism().distance_to_path(p_mm / u) * u;
}

Vec3 ClosedLoop::nearest_on_path_mm(const Vec3& p_mm) const {
  const double u = case_.controller_params().length_unit_mm;
  return controller().mechanism().nearest_on_path(p_mm / u) * u;
}

void ClosedLoop::tick(TickRecord* row) {
  // the script's clock (the physics' own, unless a run skipped ahead)
  const double t = script_time_s();
  const double t_physics = time_s();
  const double t_script = std::min(t, case_.config().sim.duration_s);
  row->segment = case_.script().segment_at(t_script);
  if (manual_hand_) {
    hand_->set_target(plant_.mutable_model(), plant_.data(), manual_target_);
    row->hand_target = wrist_pose_of(manual_target_);
  } else {
    // the script's pose at t_script, which the hand's target was made from
    row->hand_target = script_target(t);
  }

  injector_->set_time_s(t);
  // the chain: the reading through the guard (and the safety layer), the
  // controller, the write; the loop's clock is simulated time
  chain_->tick(t, t_physics, row);
  // what the (possibly injected) sensor said, even where the guard refused
  row->q_dh = device_to_dh_joints(injector_->last_reading());
  row->fault_injected = injector_->active();
  row->motor_torque_Nm = device_->motor_torque_Nm();
  const OmniParams& omni = case_.controller_params().omni;
  row->q_true_dh = device_->true_q_dh();
  OmniPose pose_true;
  omni_fk_jacobian(omni, row->q_true_dh, &pose_true, nullptr);
  row->p_true_mm = base_to_device_mm(omni, pose_true.p_base_m);
  row->nearest_true_mm = nearest_on_path_mm(row->p_true_mm);

  const int n = draw_substeps();
  const bool steps_finite = plant_.step(n, t);
  row->substeps = n;
  row->period_s = n * plant_.model()->opt.timestep;
  row->energy_motor_J = plant_.energy_motor_J();
  row->energy_hand_J = plant_.energy_hand_J();
  row->kinetic_J = plant_.kinetic_J();
  // MuJoCo resets a bad state, so the state after the tick may look fine
  row->state_finite = steps_finite && plant_.state_finite();
  row->hand_force_N = base_to_device_vector(hand_->force_N());
  row->has_truth = true;
  ++tick_count_;
  substep_count_ += n;
}

}  // namespace vmh::sim
