// bringup/response_sim: the simulated response to a torque step
// against the closed form of its first milliseconds, a(0) = M^-1 B tau
// (MuJoCo's own mass matrix and actuator moments, not the stepping code),
// and the delay and scale hypotheses against the plain response shifted
// and scaled.
#include "bringup/response_sim.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "controller/device_frame.h"
#include "sim/closed_loop.h"
#include "sim/mujoco_util.h"

namespace vmh::bringup {
namespace {

const std::string kScene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
const Joints kQ0 = (Joints() << 0.1, 0.2, 0.5, 0.1, 0.3, -0.2).finished();  // device

ResponseInput step_input(const Vec3& tau_Nm, double duration_s) {
  ResponseInput in;
  in.q0_device_rad = kQ0;
  for (int k = 0; k * 1e-3 <= duration_s + 1e-12; ++k) {
    in.t_s.push_back(1.0 + k * 1e-3);  // a recording's clock need not start at 0
    in.tau_motor_Nm.push_back(tau_Nm);
  }
  return in;
}

// frictionless and undamped, so that the closed form holds exactly
sim::OmniModelEdit ideal() {
  sim::OmniModelEdit e;
  e.friction_scale = 1e-12;
  e.damping_scale = 1e-12;
  return e;
}

// M^-1 B tau at kQ0 in device joint rates (rad/s^2), from MuJoCo directly
Joints closed_form_acceleration(const Vec3& tau_Nm) {
  // the scene's model with the hand's mass on the grip, as the loop has it
  sim::ClosedLoop loop(kScene, {}, sim::omni_model_hook("", ideal()));
  const mjModel* m = loop.model();
  mjData* d = mj_makeData(m);
  const Joints q_dh = device_to_dh_joints(kQ0);
  for (int i = 0; i < 6; ++i) {
    d->qpos[m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, sim::kOmniJoints[i])]] = q_dh[i];
  }
  mj_forward(m, d);
  const int nv = m->nv;
  Eigen::MatrixXd M(nv, nv);
  mj_fullM(m, M.data(), d->qM);  // symmetric: row/column order moot
  Eigen::VectorXd f = Eigen::VectorXd::Zero(nv);
  for (int a = 0; a < 3; ++a) {
    const int id = mj_name2id(m, mjOBJ_ACTUATOR, sim::kOmniMotors[a]);
    for (int v = 0; v < nv; ++v) f[v] += d->actuator_moment[id * nv + v] * tau_Nm[a];
  }
  const Eigen::VectorXd qacc = M.ldlt().solve(f);
  Joints a_dh;
  for (int i = 0; i < 6; ++i) {
    a_dh[i] = qacc[m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, sim::kOmniJoints[i])]];
  }
  mj_deleteData(d);
  return dh_to_device_joints(a_dh);
}

TEST(ResponseSim, EarlyResponseFollowsTheMassMatrix) {
  ResponseSimulator sim(kScene);
  // The most 4 ms of constant acceleration a from rest can move the arm:
  // a t^2 / 2 with t = 4 ms in continuous time (RK4 is exact for it); the
  // case scenes step with semi-implicit Euler at h = 1 ms, whose n steps
  // give v_k = k a h and q_n = a h^2 n (n + 1) / 2, so t_eff = h sqrt(n (n
  // + 1)) = 4.47 ms (docs/numerics.md: a quarter more than the continuous
  // plant over so short a window; the fits are consistent with the
  // emulator, which steps the same scene)
  double t_max = 0.0041;
  {
    const sim::ClosedLoop loop(kScene, {});
    const double h = loop.model()->opt.timestep;
    if (loop.model()->opt.integrator == mjINT_EULER) {
      const double n = std::round(0.004 / h);
      t_max = h * std::sqrt(n * (n + 1.0)) * 1.0001;
    }
  }
  for (const Vec3& tau : {Vec3(0.05, 0, 0), Vec3(0, 0.05, 0), Vec3(0, 0, 0.05)}) {
    const SimulatedResponse r = sim.simulate(step_input(tau, 0.004), ideal());
    ASSERT_TRUE(r.finite);
    const Joints dq = r.q_device_rad.back() - kQ0;
    // constant acceleration from rest, less whatever delay the scene's
    // device has: dq = a (t - delay)^2 / 2, in direction exactly a's
    const Joints a = closed_form_acceleration(tau);
    const double cosine = dq.dot(a) / (dq.norm() * a.norm());
    EXPECT_GT(cosine, 0.999) << "motor torque " << tau.transpose();
    const double t_eff = std::sqrt(2.0 * dq.norm() / a.norm());
    EXPECT_GT(t_eff, 0.0025) << "response too small for 4 ms";
    EXPECT_LT(t_eff, t_max) << "response larger than the closed form allows";
  }
}

TEST(ResponseSim, AtRestWithoutTorqueItStaysPut) {
  ResponseSimulator sim(kScene);
  const SimulatedResponse r = sim.simulate(step_input(Vec3::Zero(), 0.05));
  EXPECT_LT((r.q_device_rad.back() - kQ0).norm(), 1e-9);
  // and the wrist where the project's FK puts kQ0 (MuJoCo's site)
  EXPECT_EQ(r.q_device_rad.size(), r.t_s.size());
}

TEST(ResponseSim, DelayAndScaleHypotheses) {
  ResponseSimulator sim(kScene);
  const ResponseInput in = step_input(Vec3(0, 0.04, 0), 0.03);
  const SimulatedResponse plain = sim.simulate(in, ideal());
  const SimulatedResponse late = sim.simulate(in, ideal(), 0.005);
  // late by 5 ms: at sample k it is where the plain one was at k - 5
  for (std::size_t k = 10; k < in.t_s.size(); k += 5) {
    EXPECT_NEAR((late.q_device_rad[k] - plain.q_device_rad[k - 5]).norm(), 0.0, 1e-9)
        << "k = " << k;
  }
  const SimulatedResponse twice = sim.simulate(in, ideal(), 0.0, 2.0);
  const Joints d1 = plain.q_device_rad[8] - kQ0, d2 = twice.q_device_rad[8] - kQ0;
  EXPECT_NEAR(d2.norm() / d1.norm(), 2.0, 0.02);
  // the edit is applied afresh each time: the plain run again is the same
  const SimulatedResponse again = sim.simulate(in, ideal());
  EXPECT_EQ((again.q_device_rad.back() - plain.q_device_rad.back()).norm(), 0.0);
}

TEST(ResponseSim, VelocityEstimateOfALine) {
  std::vector<double> t;
  std::vector<Joints> q;
  for (int k = 0; k < 21; ++k) {
    t.push_back(0.001 * k);
    q.push_back(Joints::Constant(0.3) + Joints::LinSpaced(6, 1.0, 6.0) * (0.001 * k));
  }
  const Joints v = velocity_estimate(t, q, 10, 0.005);
  EXPECT_LT((v - Joints::LinSpaced(6, 1.0, 6.0)).norm(), 1e-9);
}

}  // namespace
}  // namespace vmh::bringup
