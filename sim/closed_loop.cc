#include "sim/closed_loop.h"

#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh::sim {
namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

// the loop whose hand the control callback drives, per thread
thread_local ClosedLoop* t_active = nullptr;

void control_callback(const mjModel* m, mjData* d) {
  if (t_active != nullptr) t_active->on_control(m, d);
}

// makes `loop` the active one for the scope, restoring the previous
class ActiveLoop {
 public:
  explicit ActiveLoop(ClosedLoop* loop) : previous_(t_active) {
    t_active = loop;
    mjcb_control = control_callback;
  }
  ~ActiveLoop() { t_active = previous_; }
  ActiveLoop(const ActiveLoop&) = delete;
  ActiveLoop& operator=(const ActiveLoop&) = delete;

 private:
  ClosedLoop* previous_;
};

// the stylus rotation (DH base frame) whose z axis is `axis_base`, reached
// from `R_ref` by the smallest rotation
Mat3 turn_to_axis(const Mat3& R_ref, const Vec3& axis_base) {
  const Eigen::Quaterniond q =
      Eigen::Quaterniond::FromTwoVectors(R_ref.col(2), axis_base);
  return q.toRotationMatrix() * R_ref;
}

}  // namespace

ClosedLoop::ClosedLoop(const std::string& scene_path,
                       const std::vector<std::string>& overrides)
    : path_(scene_path),
      model_(load_model(scene_path)),
      config_(CaseConfig::from_model(model_.get(), scene_path, overrides)) {
  mjModel* m = model_.get();
  const double h_set = config_.number("physics_step_s");
  if (h_set > 0.0) m->opt.timestep = h_set;
  const std::string& integrator = config_.text("integrator");
  if (integrator == "euler") m->opt.integrator = mjINT_EULER;
  if (integrator == "implicit") m->opt.integrator = mjINT_IMPLICIT;
  if (integrator == "rk4") m->opt.integrator = mjINT_RK4;
  const double T = config_.number("servo_period_s");
  const double h = m->opt.timestep;
  const double n = std::round(T / h);
  if (n < 1.0 || std::abs(n * h - T) > 1e-9 * T) {
    throw SimError(path_ + ": servo_period_s (" + std::to_string(T) +
                   " s) must be a whole multiple of the physics step (" +
                   std::to_string(h) + " s)");
  }
  substeps_ = static_cast<int>(n);
  ticks_per_run_ =
      static_cast<int>(std::llround(config_.number("duration_s") / T));

  data_.reset(mj_makeData(m));
  if (!data_) throw SimError(path_ + ": mj_makeData failed");
  hand_ = std::make_unique<SimHand>(m, data_.get(), hand_params(config_), path_);

  params_ = sim::controller_params(config_);
  try {
    params_.validate();
    controller_ = std::make_unique<Controller>(params_);
  } catch (const std::invalid_argument& e) {
    throw SimError(path_ + ": " + e.what());
  }
  device_ = std::make_unique<SimDevice>(
      m, data_.get(), params_.omni, config_.number("quantize") != 0.0,
      static_cast<int>(config_.number("delay_ticks")), path_);
  script_ = std::make_unique<HandScript>(config_, params_.vm);

  // the start pose: the script's first target, the stylus turned the least
  // from its home frame; the IK solution nearest the home pose
  const OmniParams& omni = params_.omni;
  const ScriptPose start = script_->at(0.0);
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
                   std::to_string(start.p_mm.x()) + ", " +
                   std::to_string(start.p_mm.y()) + ", " +
                   std::to_string(start.p_mm.z()) +
                   ") mm cannot be reached within the joint ranges; change "
                   "script_dir, vm_pivot_mm or vm_length_mm");
  }
  q_start_dh_ = ik.q_dh[static_cast<std::size_t>(best)];
  reset();
}

ClosedLoop::~ClosedLoop() {
  if (t_active == this) t_active = nullptr;
}

void ClosedLoop::set_reference(const ControllerParams& params) {
  reference_ = std::make_unique<Controller>(params);
}

double ClosedLoop::time_s() const {
  return static_cast<double>(tick_count_) * params_.servo_period_s;
}

void ClosedLoop::reset() {
  mjModel* m = model_.get();
  mjData* d = data_.get();
  mj_resetData(m, d);
  device_->reset();
  tick_count_ = 0;
  controller_->reset();
  if (reference_) reference_->reset();
  // write the start angles through the joint addresses
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    d->qpos[m->jnt_qposadr[j]] = q_start_dh_[i];
  }
  set_hand_target(0.0);
  ActiveLoop active(this);
  mj_forward(m, d);
}

void ClosedLoop::set_hand_target(double t_s) {
  const OmniParams& omni = params_.omni;
  const mjModel* m = model_.get();
  // the grip site's offset and rotation in the stylus body
  const int g = hand_->grip_site();
  const Vec3 grip_local(m->site_pos + 3 * g);
  RowMat3 R_site;
  mju_quat2Mat(R_site.data(), m->site_quat + 4 * g);

  auto target_at = [&](double t, Vec3* p_grip, Mat3* R_grip) {
    const ScriptPose pose = script_->at(t);
    const Mat3 R = turn_to_axis(R_start_base_, device_to_base_vector(pose.axis));
    // the stylus body's origin is the wrist centre
    const Vec3 wrist = device_mm_to_base(omni, pose.p_mm);
    *p_grip = wrist + R * grip_local;
    *R_grip = R * R_site;
  };
  HandTargetState target;
  target_at(t_s, &target.p_m, &target.R);
  // the target's velocity by a forward difference over a small interval
  const double dt = 1e-5;
  Vec3 p2;
  Mat3 R2;
  target_at(t_s + dt, &p2, &R2);
  target.v_m_s = (p2 - target.p_m) / dt;
  const Eigen::AngleAxisd dR(R2 * target.R.transpose());
  target.w_rad_s = dR.angle() * dR.axis() / dt;
  hand_->set_target(m, data_.get(), target);
}

void ClosedLoop::on_control(const mjModel* m, mjData* d) {
  if (d == data_.get()) hand_->apply(m, d);
}

double ClosedLoop::distance_to_path_mm(const Vec3& p_mm) const {
  const VmParams& vm = params_.vm;
  const Vec3 r = vm.R_pivot.transpose() * (p_mm - vm.pivot_mm);
  switch (vm.kind) {
    case VmKind::kCircle: {
      const double rho = std::hypot(r.x(), r.y());
      return std::hypot(rho - vm.length_mm, r.z());
    }
    case VmKind::kSphere:
      return std::abs(r.norm() - vm.length_mm);
    case VmKind::kSurface:
      // the handle stays L from the plane when the probe is upright
      return std::abs(std::abs(r.z()) - vm.length_mm);
  }
  return 0.0;
}

Vec3 ClosedLoop::nearest_on_path_mm(const Vec3& p_mm) const {
  const VmParams& vm = params_.vm;
  Vec3 r = vm.R_pivot.transpose() * (p_mm - vm.pivot_mm);
  switch (vm.kind) {
    case VmKind::kCircle:
      r.z() = 0.0;
      break;
    case VmKind::kSphere:
      break;
    case VmKind::kSurface:
      r.z() = r.z() >= 0.0 ? vm.length_mm : -vm.length_mm;
      return vm.pivot_mm + vm.R_pivot * r;
  }
  // at the pivot every point of the path is nearest; keep the pivot
  if (r.norm() < 1e-12) return vm.pivot_mm;
  return vm.pivot_mm + vm.R_pivot * (vm.length_mm * r.normalized());
}

void ClosedLoop::tick(TraceRow* row) {
  ActiveLoop active(this);
  const double t = time_s();
  row->t_s = t;
  set_hand_target(t);
  row->segment = script_->segment_at(t);
  row->hand_target = script_->at(t);

  row->servo = servo_tick(device_.get(), controller_.get(), &row->out);
  row->q_dh = device_to_dh_joints(device_->sensor().measure(
      dh_to_device_joints(device_->true_q_dh())));
  if (reference_) {
    reference_->tick(row->q_dh, &reference_out_);
    row->force_reference_N = reference_out_.force_device_N;
  }
  row->motor_torque_Nm = device_->motor_torque_Nm();
  row->d_path_mm = distance_to_path_mm(row->out.p_rm_mm);
  const OmniParams& omni = params_.omni;
  row->p_true_mm =
      base_to_device_mm(omni, omni_fk(omni, device_->true_q_dh()).p_base_m);
  row->nearest_true_mm = nearest_on_path_mm(row->p_true_mm);

  mjModel* m = model_.get();
  mjData* d = data_.get();
  for (int i = 0; i < substeps_; ++i) mj_step(m, d);
  row->hand_force_N = base_to_device_vector(hand_->force_N());
  ++tick_count_;
}

}  // namespace vmh::sim
