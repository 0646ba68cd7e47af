#include "bringup/response_sim.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "controller/device_frame.h"
#include "sim/cases/case.h"
#include "sim/closed_loop.h"
#include "sim/emulator_hand.h"
#include "sim/mujoco_util.h"

namespace vmh::bringup {

ResponseSimulator::ResponseSimulator(const std::string& scene,
                                     const std::string& model_file)
    : scene_(scene), model_file_(model_file) {
  servo_period_s_ = sim::load_case(scene, {}, sim::omni_model_hook(model_file))
                        .controller_params()
                        .servo_period_s;
}

ResponseSimulator::~ResponseSimulator() = default;

double ResponseSimulator::servo_period_s() const { return servo_period_s_; }

SimulatedResponse ResponseSimulator::simulate(const ResponseInput& in,
                                              const sim::OmniModelEdit& edit,
                                              double extra_delay_s,
                                              double torque_scale) {
  if (in.t_s.size() != in.tau_motor_Nm.size() || in.t_s.empty()) {
    throw std::invalid_argument(
        "simulate_response: t_s and tau_motor_Nm must be non-empty and of one length");
  }
  // the scene loaded afresh: the edit applies to the Omni as written
  sim::ClosedLoop loop(scene_, {}, sim::omni_model_hook(model_file_, edit));
  const mjModel* m = loop.model();
  mjData* d = loop.data();
  const Joints q_dh = device_to_dh_joints(in.q0_device_rad);
  // the map is linear, so it maps rates as it maps angles
  const Joints qd_dh = device_to_dh_joints(in.qdot0_device_rad_s);
  for (int i = 0; i < 6; ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, sim::kOmniJoints[i]);
    d->qpos[m->jnt_qposadr[j]] = q_dh[i];
    d->qvel[m->jnt_dofadr[j]] = qd_dh[i];
  }
  mj_forward(m, d);
  sim::EmulatorHand hand(&loop);
  sim::SimDevice& dev = loop.device();
  const int substeps = loop.substeps();
  const double T = servo_period_s();
  const int wrist = mj_name2id(m, mjOBJ_SITE, "wrist");
  const OmniParams omni;

  // one write and `substeps` physics steps per servo period, as the
  // emulator runs (SimDevice's delay line counts writes); the state at the
  // period ends, interpolated to the sample times
  const double t0 = in.t_s.front();
  const long periods = std::lround((in.t_s.back() - t0) / T) + 1;
  std::vector<Joints> q_end;
  std::vector<Vec3> p_end;
  q_end.reserve(static_cast<std::size_t>(periods) + 1);
  p_end.reserve(static_cast<std::size_t>(periods) + 1);
  auto keep = [&]() {
    q_end.push_back(dh_to_device_joints(dev.true_q_dh()));
    p_end.push_back(base_to_device_mm(omni, Vec3(d->site_xpos + 3 * wrist)));
  };
  keep();
  std::size_t cmd = 0;
  bool finite = true;
  for (long k = 0; k < periods && finite; ++k) {
    const double t_cmd = t0 + static_cast<double>(k) * T - extra_delay_s + 1e-9;
    while (cmd + 1 < in.t_s.size() && in.t_s[cmd + 1] <= t_cmd) ++cmd;
    const Vec3 tau = t_cmd >= t0 ? Vec3(torque_scale * in.tau_motor_Nm[cmd])
                                 : Vec3::Zero();
    dev.write_motor_torques(tau);
    for (int i = 0; i < substeps; ++i) {
      hand.let_go();
      mj_step(m, d);
    }
    keep();
    finite = q_end.back().allFinite();
  }

  SimulatedResponse out;
  out.t_s = in.t_s;
  out.finite = finite;
  for (double t : in.t_s) {
    const double x = std::clamp((t - t0) / T, 0.0, static_cast<double>(q_end.size() - 1));
    const std::size_t i = std::min(static_cast<std::size_t>(x), q_end.size() - 1);
    const std::size_t j = std::min(i + 1, q_end.size() - 1);
    const double w = x - static_cast<double>(i);
    out.q_device_rad.push_back((1.0 - w) * q_end[i] + w * q_end[j]);
    out.p_mm.push_back((1.0 - w) * p_end[i] + w * p_end[j]);
  }
  return out;
}

Joints velocity_estimate(const std::vector<double>& t_s,
                         const std::vector<Joints>& q, std::size_t k,
                         double half_window_s) {
  double st = 0.0, stt = 0.0, n = 0.0;
  Joints sq = Joints::Zero(), stq = Joints::Zero();
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    const double dt = t_s[i] - t_s[k];
    if (std::abs(dt) > half_window_s || !q[i].allFinite()) continue;
    n += 1.0;
    st += dt;
    stt += dt * dt;
    sq += q[i];
    stq += dt * q[i];
  }
  const double den = n * stt - st * st;
  if (n < 2.0 || den <= 0.0) return Joints::Zero();
  return (n * stq - st * sq) / den;
}

}  // namespace vmh::bringup
