#include "tests/bringup/synthetic_recording.h"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "controller/omni_params.h"
#include "sim/sensor_model.h"
#include "tests/support/constants.h"

namespace vmh::testing {
namespace {

using vmh::testing::kPi;
constexpr double kNominalLinkMm = 133.35;

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
using RowJac = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>;

// DH base -> device frame rotation, written out (docs/sources.md §4)
Mat3 base_to_device() {
  Mat3 P;
  P << 0, 1, 0,
       0, 0, 1,
       1, 0, 0;
  return P;
}

// d q_dh / d t_device: q1 = -t1, q2 = t2, q3 = t3 - t2, q4 = -t4, q5 = t5,
// q6 = -t6 (docs/sources.md §4)
Mat6 dq_dt() {
  Mat6 M = Mat6::Zero();
  M(0, 0) = -1;
  M(1, 1) = 1;
  M(2, 1) = -1;
  M(2, 2) = 1;
  M(3, 3) = -1;
  M(4, 4) = 1;
  M(5, 5) = -1;
  return M;
}

Joints device_from_dh(const Joints& q) {
  Joints t;
  t << -q[0], q[1], q[1] + q[2], -q[3], q[4], -q[5];
  return t;
}

Joints dh_from_device(const Joints& t) {
  Joints q;
  q << -t[0], t[1], t[2] - t[1], -t[3], t[4], -t[5];
  return q;
}

void put(bringup::Recording* r, const std::string& name, double v) {
  if (r->num.count(name) == 0) r->columns.push_back(name);
  r->num[name].push_back(v);
}

}  // namespace

std::vector<SyntheticSample> tour_motion(double duration_s, double rate_hz,
                                         double delay_s) {
  const OmniParams p;
  const double f_hz[6] = {0.23, 0.31, 0.41, 0.37, 0.53, 0.29};
  const double phase_rad[6] = {0.0, 1.1, 2.3, 0.7, 1.9, 2.9};
  std::vector<SyntheticSample> out;
  const int n = static_cast<int>(std::floor(duration_s * rate_hz)) + 1;
  for (int k = 0; k < n; ++k) {
    SyntheticSample s;
    s.t_s = k / rate_hz;
    const double t = s.t_s - delay_s;
    for (int i = 0; i < 6; ++i) {
      const double c = 0.5 * (p.joint_lower_rad[i] + p.joint_upper_rad[i]);
      const double a = 0.7 * 0.5 * (p.joint_upper_rad[i] - p.joint_lower_rad[i]);
      const double w = 2 * kPi * f_hz[i];
      s.q_dh_rad[i] = c + a * std::sin(w * t + phase_rad[i]);
      s.qdot_dh_rad_s[i] = a * w * std::cos(w * t + phase_rad[i]);
    }
    out.push_back(s);
  }
  return out;
}

bringup::Recording synthetic_recording(const mjModel* m,
                                       const std::vector<SyntheticSample>& motion,
                                       const SyntheticOptions& o) {
  const int site = mj_name2id(m, mjOBJ_SITE, "wrist");
  if (site < 0) throw std::invalid_argument("synthetic_recording: no site 'wrist'");
  mjData* d = mj_makeData(m);
  const sim::SensorModel sensors(OmniParams{}, o.quantize);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_rad > 0 ? o.noise_rad : 1.0);
  const Mat3 P = base_to_device();
  const Mat6 M = dq_dt();

  bringup::Recording r;
  r.dir = "synthetic";
  r.verb = "hw record";
  r.meta = {{"verb", r.verb}};
  r.text["read_error"] = {};
  r.columns.push_back("read_error");
  for (const SyntheticSample& s : motion) {
    for (int i = 0; i < 6; ++i) d->qpos[i] = s.q_dh_rad[i];
    mj_kinematics(m, d);
    mj_comPos(m, d);
    Joints sensed = sensors.measure(device_from_dh(s.q_dh_rad));
    for (int i = 3; i < 6; ++i) sensed[i] *= o.gimbal_gain[i - 3];
    Joints t = o.map.reported_from_true(sensed);
    t += o.reported_offset_device_rad;
    if (o.noise_rad > 0) {
      for (int i = 0; i < 6; ++i) t[i] += noise(rng);
    }
    const Joints q_rep = dh_from_device(t);

    put(&r, "t_s", s.t_s);
    for (int i = 0; i < 6; ++i) put(&r, "q" + std::to_string(i + 1) + "_rad", q_rep[i]);
    for (int i = 1; i <= 3; ++i) put(&r, "tau_sent_" + std::to_string(i) + "_Nm", 0.0);
    r.text["read_error"].push_back("ok");

    const Vec3 p_base_mm = Eigen::Map<const Vec3>(d->site_xpos + 3 * site) * 1000.0;
    const Mat3 R_dev = P * Mat3(Eigen::Map<const RowMat3>(d->site_xmat + 9 * site)) *
                       o.rotation_convention;
    RowJac jp, jr;
    mj_jacSite(m, d, jp.data(), jr.data(), site);
    Mat6 J_q;
    J_q.topRows<3>() = P * jp * 1000.0;
    J_q.bottomRows<3>() = P * jr;
    if (o.transform) {
      const Vec3 p = P * p_base_mm + Vec3(0, kNominalLinkMm, -kNominalLinkMm) +
                     o.origin_offset_mm;
      const char* xyz[] = {"x", "y", "z"};
      for (int i = 0; i < 3; ++i) put(&r, std::string("dev_p_") + xyz[i] + "_mm", p[i]);
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          put(&r, "dev_R_" + std::to_string(a + 1) + std::to_string(b + 1), R_dev(a, b));
        }
      }
    }
    if (o.velocity) {
      const Vec3 v = J_q.topRows<3>() * s.qdot_dh_rad_s;
      const char* xyz[] = {"x", "y", "z"};
      for (int i = 0; i < 3; ++i) put(&r, std::string("dev_v_") + xyz[i] + "_mm_s", v[i]);
    }
    if (o.jacobian) {
      Mat6 J = o.jacobian_dh_columns ? J_q : Mat6(J_q * M);
      if (o.jacobian_transposed) J.transposeInPlace();
      for (int a = 0; a < 6; ++a) {
        for (int b = 0; b < 6; ++b) {
          put(&r, "dev_J_" + std::to_string(a + 1) + std::to_string(b + 1), J(a, b));
        }
      }
    }
    ++r.rows;
  }
  mj_deleteData(d);
  return r;
}

}  // namespace vmh::testing
