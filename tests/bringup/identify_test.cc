// bringup/identify: motor-test recordings synthesized under a known
// ("true") model edit, quantized like the sensors, and the fit asked to
// find that edit again; the calibrated model written and read back against
// the edit applied directly.
#include "bringup/identify.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_params.h"
#include "sim/mujoco_util.h"
#include "sim/sensor_model.h"
#include "bringup/response_sim.h"

namespace vmh::bringup {
namespace {

const std::string kScene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
const std::string kOmniXml = std::string(VMH_MODELS_DIR) + "/omni/omni.xml";
// device angles, t3 absolute: arm mid-range, gimbal off its zero
const Joints kQ0 = (Joints() << 0.0, 0.2, 0.4, 0.1, -0.2, 0.3).finished();

struct Pulse {
  int motor;          // 1..3
  double torque_Nm;
  double length_s;
};

// A motor test as `hw motor-test` records it: rest, one pulse, rest; the
// angles simulated under `truth` and read through the sensor model
Recording synthesize(ResponseSimulator* sim, const Pulse& pulse,
                     const sim::OmniModelEdit& truth) {
  const double t_on_s = 0.05, t_total_s = t_on_s + pulse.length_s + 0.35;
  ResponseInput in;
  in.q0_device_rad = kQ0;
  for (int k = 0; k * 1e-3 <= t_total_s; ++k) {
    const double t = 2.0 + k * 1e-3;  // a device clock need not start at 0
    Vec3 tau = Vec3::Zero();
    if (k * 1e-3 >= t_on_s - 1e-9 && k * 1e-3 < t_on_s + pulse.length_s - 1e-9) {
      tau[pulse.motor - 1] = pulse.torque_Nm;
    }
    in.t_s.push_back(t);
    in.tau_motor_Nm.push_back(tau);
  }
  const sim::SensorModel sensors(OmniParams(), true);
  const SimulatedResponse truth_run = sim->simulate(in, truth);
  EXPECT_TRUE(truth_run.finite);

  Recording r;
  r.dir = "synth/motor" + std::to_string(pulse.motor);
  r.verb = "hw motor-test";
  r.meta = {{"verb", r.verb},
            {"motor", pulse.motor},
            {"emulator", {{"scene", kScene}}},
            {"device", {{"serial", "TEST-0001"}}}};
  r.columns = {"t_s"};
  for (int i = 1; i <= 6; ++i) r.columns.push_back("q" + std::to_string(i) + "_rad");
  for (int i = 1; i <= 3; ++i) r.columns.push_back("tau_sent_" + std::to_string(i) + "_Nm");
  r.columns.push_back("read_error");
  r.rows = in.t_s.size();
  for (std::size_t k = 0; k < r.rows; ++k) {
    r.num["t_s"].push_back(in.t_s[k]);
    const Joints q_dh = device_to_dh_joints(sensors.measure(truth_run.q_device_rad[k]));
    for (int i = 0; i < 6; ++i) r.num["q" + std::to_string(i + 1) + "_rad"].push_back(q_dh[i]);
    for (int i = 0; i < 3; ++i) {
      r.num["tau_sent_" + std::to_string(i + 1) + "_Nm"].push_back(in.tau_motor_Nm[k][i]);
    }
    r.text["read_error"].push_back("ok");
  }
  return r;
}

std::vector<Recording> motor_tests(const sim::OmniModelEdit& truth) {
  ResponseSimulator sim(kScene);
  std::vector<Recording> out;
  for (const Pulse& p : {Pulse{1, 0.06, 0.06}, Pulse{2, 0.08, 0.06}, Pulse{3, -0.06, 0.06}}) {
    out.push_back(synthesize(&sim, p, truth));
  }
  return out;
}

const FittedParameter& param(const IdentifyResult& r, const std::string& name) {
  for (const FittedParameter& p : r.parameters) {
    if (p.name == name) return p;
  }
  throw std::runtime_error("no parameter " + name);
}

TEST(Identify, RecoversSeededMassAndFriction) {
  sim::OmniModelEdit truth;
  truth.mass_scale = 2.0;
  truth.friction_scale = 3.0;
  const IdentifyResult r = identify(motor_tests(truth), IdentifyOptions{});
  ASSERT_TRUE(r.converged);
  const FittedParameter& m = param(r, "mass_scale");
  const FittedParameter& f = param(r, "friction_scale");
  EXPECT_NEAR(m.fitted, 2.0, 0.10 * 2.0);  // the stated tolerances
  EXPECT_NEAR(f.fitted, 3.0, 0.20 * 3.0);
  // the reported confidence covers the error actually made
  EXPECT_LT(std::abs(m.fitted - 2.0), 4.0 * m.sigma);
  EXPECT_LT(std::abs(f.fitted - 3.0), 4.0 * f.sigma);
  EXPECT_TRUE(m.identified);
  EXPECT_TRUE(f.identified);
  // the model's damping is small and short pulses barely see it: the fit
  // must not claim it
  EXPECT_FALSE(param(r, "damping_scale").identified);
  // the fit explains the recordings far better than the nominal model
  ASSERT_EQ(r.recordings.size(), 3u);
  for (const RecordingFit& rf : r.recordings) {
    EXPECT_LT(rf.rms_after_rad, 0.2 * rf.rms_before_rad) << rf.dir;
    EXPECT_LT(rf.rms_after_mm, 0.2 * rf.rms_before_mm) << rf.dir;
  }
  EXPECT_LT(r.cost_after, r.cost_before);
  EXPECT_FALSE(r.poorly_conditioned) << r.conditioning;
  for (const MotorSign& s : r.signs) {
    EXPECT_EQ(s.sign, 1) << "motor " << s.motor;
    EXPECT_TRUE(s.determined) << "motor " << s.motor;
  }
  ASSERT_EQ(r.signs.size(), 3u);
  std::printf("seeded x2/x3: mass %.4f +- %.4f, friction %.4f +- %.4f, damping %.3f +- %.3f; "
              "cost %.3g -> %.3g; sigma x%.2f; %s\n",
              m.fitted, m.sigma, f.fitted, f.sigma, param(r, "damping_scale").fitted,
              param(r, "damping_scale").sigma, r.cost_before, r.cost_after, r.sigma_inflation,
              r.conditioning.c_str());
  for (const RecordingFit& rf : r.recordings) {
    std::printf("  %s: rms %.4g -> %.4g rad, %.4g -> %.4g mm\n", rf.dir.c_str(),
                rf.rms_before_rad, rf.rms_after_rad, rf.rms_before_mm, rf.rms_after_mm);
  }
}

TEST(Identify, CleanSetGivesTheModelAsWrittenAndFindsAFlippedMotor) {
  sim::OmniModelEdit truth;
  truth.motor_gain[1] = -1.0;  // motor 2 wired the other way round
  IdentifyOptions o;
  o.fit = {"mass", "friction"};
  const IdentifyResult r = identify(motor_tests(truth), o);
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(r.signs.size(), 3u);
  for (const MotorSign& s : r.signs) {
    EXPECT_EQ(s.sign, s.motor == 2 ? -1 : 1) << "motor " << s.motor;
    EXPECT_TRUE(s.determined) << "motor " << s.motor;
  }
  EXPECT_LT(r.edit.motor_gain[1], 0.0);
  EXPECT_NEAR(param(r, "mass_scale").fitted, 1.0, 0.05);
  EXPECT_NEAR(param(r, "friction_scale").fitted, 1.0, 0.10);
  std::printf("clean, motor 2 flipped: mass %.4f +- %.4f, friction %.4f +- %.4f\n",
              param(r, "mass_scale").fitted, param(r, "mass_scale").sigma,
              param(r, "friction_scale").fitted, param(r, "friction_scale").sigma);
}

TEST(Identify, MassWithGainsIsReportedPoorlyConditioned) {
  sim::OmniModelEdit truth;
  truth.mass_scale = 2.0;
  IdentifyOptions o;
  o.fit = {"mass", "friction", "gains"};
  o.max_iterations = 3;  // the flag does not wait for the fit
  const IdentifyResult r = identify(motor_tests(truth), o);
  // masses and gains scaled together move the arm alike but for the
  // unscaled armature and hand: the fit must say so, and its matrix must
  // be a correlation matrix over the five parameters
  EXPECT_TRUE(r.poorly_conditioned);
  EXPECT_NE(r.conditioning.find("armature"), std::string::npos) << r.conditioning;
  ASSERT_EQ(r.correlation.rows(), 5);
  EXPECT_LT((r.correlation - r.correlation.transpose()).norm(), 1e-9);
  EXPECT_LT((r.correlation.diagonal() - Eigen::VectorXd::Ones(5)).norm(), 1e-9);
  EXPECT_LE(r.correlation.cwiseAbs().maxCoeff(), 1.0 + 1e-9);
  EXPECT_GE(r.condition_number, 1.0);
  std::printf("mass + gains: %s\n", r.conditioning.c_str());
}

TEST(Identify, BadInputIsNamed) {
  EXPECT_THROW(identify({}, IdentifyOptions{}), IdentifyError);
  std::vector<Recording> recs = motor_tests({});
  recs.resize(1);
  for (double& v : recs[0].num["tau_sent_1_Nm"]) v = 0.0;
  try {
    identify(recs, IdentifyOptions{});
    ADD_FAILURE() << "no pulse accepted";
  } catch (const IdentifyError& e) {
    EXPECT_NE(std::string(e.what()).find("synth/motor1"), std::string::npos) << e.what();
  }
  IdentifyOptions bad;
  bad.fit = {"mass", "inertia"};
  try {
    identify(motor_tests({}), bad);
    ADD_FAILURE() << "unknown name accepted";
  } catch (const IdentifyError& e) {
    EXPECT_NE(std::string(e.what()).find("'inertia'"), std::string::npos) << e.what();
  }
}

TEST(Identify, CalibratedModelCarriesTheFit) {
  sim::OmniModelEdit fit;
  fit.mass_scale = 1.87;
  fit.friction_scale = 3.3;
  fit.damping_scale = 0.6;
  fit.motor_gain = Vec3(1.0, -1.0, 1.0);
  const std::string out = ::testing::TempDir() + "/identify_test_calibrated.xml";
  write_calibrated_model(fit, kOmniXml, out, "serial TEST-0001, fitted -- a test");
  std::ifstream in(out);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  EXPECT_NE(second.find("<!-- serial TEST-0001"), std::string::npos) << second;

  // into a case scene by copy, against the edit applied to it directly
  sim::ModelPtr copied = sim::load_model(kScene);
  sim::copy_omni_parameters(copied.get(), sim::load_model(out).get(), out);
  sim::ModelPtr direct = sim::load_model(kScene);
  sim::apply_omni_edit(direct.get(), fit);
  auto near = [](double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b)); };
  for (const char* name : sim::kOmniBodies) {
    const int a = mj_name2id(copied.get(), mjOBJ_BODY, name);
    const int b = mj_name2id(direct.get(), mjOBJ_BODY, name);
    EXPECT_TRUE(near(copied->body_mass[a], direct->body_mass[b])) << name;
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(near(copied->body_inertia[3 * a + k], direct->body_inertia[3 * b + k])) << name;
    }
  }
  for (const char* name : sim::kOmniJoints) {
    const int a = copied->jnt_dofadr[mj_name2id(copied.get(), mjOBJ_JOINT, name)];
    const int b = direct->jnt_dofadr[mj_name2id(direct.get(), mjOBJ_JOINT, name)];
    EXPECT_TRUE(near(copied->dof_frictionloss[a], direct->dof_frictionloss[b])) << name;
    EXPECT_TRUE(near(copied->dof_damping[a], direct->dof_damping[b])) << name;
  }
  for (const char* name : sim::kOmniMotors) {
    const int a = mj_name2id(copied.get(), mjOBJ_ACTUATOR, name);
    const int b = mj_name2id(direct.get(), mjOBJ_ACTUATOR, name);
    EXPECT_TRUE(near(copied->actuator_gear[6 * a], direct->actuator_gear[6 * b])) << name;
  }
  std::remove(out.c_str());
}

}  // namespace
}  // namespace vmh::bringup
