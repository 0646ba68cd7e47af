#include "bringup/geometry_fit.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"

namespace vmh::bringup {
namespace {

using constants::kPi;
constexpr double kFitRadToDeg = 180.0 / kPi;

// The angle of a rotation from its skew and symmetric parts: acos of the
// trace alone turns entry noise of 1e-4 into a degree near zero
double rotation_angle_rad(const Mat3& R) {
  const Vec3 s(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * s.norm(), 0.5 * (R.trace() - 1.0));
}

// The best fixed C over the samples (R_device ~ R_model C): the orthogonal
// Procrustes solution of sum R_model^T R_device
Mat3 estimate_convention(const GeometryVec& x, const std::vector<PoseSample>& s) {
  Mat3 M = Mat3::Zero();
  for (const PoseSample& p : s) {
    Vec3 pm;
    Mat3 Rm;
    geometry_model(x, p.t_reported_device_rad, &pm, &Rm);
    M += Rm.transpose() * p.R_device;
  }
  Eigen::JacobiSVD<Mat3> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

// the nearest signed permutation with det +1, if C is within 10 deg of it
bool snap_to_signed_permutation(Mat3* C) {
  Mat3 P = Mat3::Zero();
  for (int r = 0; r < 3; ++r) {
    int c;
    C->row(r).cwiseAbs().maxCoeff(&c);
    P(r, c) = (*C)(r, c) > 0 ? 1.0 : -1.0;
  }
  if ((P.transpose() * P - Mat3::Identity()).norm() > 1e-9 || P.determinant() < 0) {
    return false;
  }
  if (rotation_angle_rad(P.transpose() * *C) > 10.0 / kFitRadToDeg) return false;
  *C = P;
  return true;
}

struct Errors {
  std::vector<double> position_mm, rotation_deg;
};

Errors sample_errors(const GeometryVec& x, const Mat3& C,
                     const std::vector<PoseSample>& s) {
  Errors e;
  for (const PoseSample& p : s) {
    Vec3 pm;
    Mat3 Rm;
    geometry_model(x, p.t_reported_device_rad, &pm, &Rm);
    e.position_mm.push_back((pm - p.p_device_mm).norm());
    e.rotation_deg.push_back(rotation_angle_rad((Rm * C).transpose() * p.R_device) *
                             kFitRadToDeg);
  }
  return e;
}

bool plausible(const GeometryVec& x) {
  const GeometryVec n = nominal_geometry();
  for (int i : {kL1, kL2}) {
    if (std::abs(x[i] / n[i] - 1.0) > 0.10) return false;
  }
  for (int i = 0; i < 6; ++i) {
    if (std::abs(x[kOffsetT1 + i]) > 0.3) return false;
  }
  for (int i = 0; i < 3; ++i) {
    if (std::abs(x[kScaleT4 + i] - 1.0) > 0.2) return false;
  }
  return true;
}

}  // namespace

GeometryVec nominal_geometry() {
  const OmniParams p;
  GeometryVec x = GeometryVec::Zero();
  x[kL1] = p.l1_m * kMmPerM;
  x[kL2] = p.l2_m * kMmPerM;
  x.tail<3>().setOnes();
  return x;
}

std::string geometry_param_name(int i) {
  static const char* kNames[kGeometryParams] = {
      "l1", "l2", "base_offset_x", "base_offset_y", "base_offset_z",
      "t1_offset", "t2_offset", "t3_offset", "t4_offset", "t5_offset",
      "t6_offset", "t4_scale", "t5_scale", "t6_scale"};
  if (i < 0 || i >= kGeometryParams) {
    throw std::invalid_argument("geometry_param_name: no parameter " + std::to_string(i));
  }
  return kNames[i];
}

std::string geometry_param_unit(int i) {
  if (i < 0 || i >= kGeometryParams) {
    throw std::invalid_argument("geometry_param_unit: no parameter " + std::to_string(i));
  }
  if (i < kOffsetT1) return "mm";
  return i < kScaleT4 ? "rad" : "1";
}

void geometry_model(const GeometryVec& x, const Joints& t_rep, Vec3* p_mm,
                    Mat3* R_device) {
  static const OmniParams kNominal;
  Joints t = t_rep;
  for (int i = 3; i < 6; ++i) t[i] *= x[kScaleT4 + i - 3];
  t += x.segment<6>(kOffsetT1);
  OmniParams params = kNominal;
  params.l1_m = x[kL1] / kMmPerM;
  params.l2_m = x[kL2] / kMmPerM;
  const OmniPose pose = omni_fk(params, device_to_dh_joints(t));
  // the device frame's origin is the nominal device's: a longer arm moves
  // the wrist, not the frame
  *p_mm = base_to_device_mm(kNominal, pose.p_base_m) + x.segment<3>(kBaseX);
  *R_device = base_to_device_rotation(pose.R_base);
}

GeometryResidual geometry_residual(const GeometryVec& x, const PoseSample& s,
                                   const Mat3& C, double w) {
  Vec3 pm;
  Mat3 Rm;
  geometry_model(x, s.t_reported_device_rad, &pm, &Rm);
  GeometryResidual r;
  r.head<3>() = pm - s.p_device_mm;
  const Mat3 dR = Rm * C - s.R_device;
  r.tail<9>() = w * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dR.data());
  return r;
}

GeometryJacobian geometry_residual_jacobian(const GeometryVec& x,
                                            const PoseSample& s, const Mat3& C,
                                            double w) {
  GeometryJacobian J;
  for (int k = 0; k < kGeometryParams; ++k) {
    // steps near the square root of the FK's rounding, scaled to the
    // parameter's size (mm or rad)
    const double h = k < kOffsetT1 ? 1e-4 : 1e-6;
    GeometryVec a = x, b = x;
    a[k] += h;
    b[k] -= h;
    J.col(k) = (geometry_residual(a, s, C, w) - geometry_residual(b, s, C, w)) / (2 * h);
  }
  return J;
}

ErrorStats error_stats(std::vector<double> v) {
  if (v.empty()) throw std::invalid_argument("error_stats: no values");
  ErrorStats e;
  e.count = v.size();
  const double n = static_cast<double>(v.size());
  double sum = 0, sum2 = 0;
  for (double a : v) {
    sum += a;
    sum2 += a * a;
    e.max = std::max(e.max, a);
  }
  e.mean = sum / n;
  e.rms = std::sqrt(sum2 / n);
  const std::size_t k =
      static_cast<std::size_t>(std::ceil(0.95 * n)) - 1;
  std::nth_element(v.begin(), v.begin() + k, v.end());
  e.p95 = v[k];
  return e;
}

namespace {

using MatP = Eigen::Matrix<double, kGeometryParams, kGeometryParams>;

// Throws std::invalid_argument with fewer than 20 samples or one that is
// not finite (its index named)
void check_pose_samples(const std::vector<PoseSample>& all) {
  if (all.size() < 20) {
    throw std::invalid_argument("fit_geometry: " + std::to_string(all.size()) +
                                " samples, at least 20 needed");
  }
  for (std::size_t i = 0; i < all.size(); ++i) {
    const PoseSample& s = all[i];
    if (!s.t_reported_device_rad.allFinite() || !s.p_device_mm.allFinite() ||
        !s.R_device.allFinite()) {
      throw std::invalid_argument("fit_geometry: sample " + std::to_string(i) +
                                  " is not finite");
    }
  }
}

// at most max(max_samples, 20) of the samples, evenly spread
std::vector<PoseSample> spread_samples(const std::vector<PoseSample>& all,
                                       std::size_t max_samples) {
  std::vector<PoseSample> s;
  const std::size_t n =
      std::min(all.size(), std::max<std::size_t>(max_samples, 20));
  for (std::size_t i = 0; i < n; ++i) s.push_back(all[i * all.size() / n]);
  return s;
}

// What the fit's Levenberg-Marquardt works on: the samples, the device's
// rotation convention C, the rotation weight w (mm/rad), which parameters
// are free, and the normal equations J^T J, J^T r as last built
struct GeometryProblem {
  GeometryProblem(const std::vector<PoseSample>& samples,
                  const Mat3& convention, double weight)
      : s(samples), C(convention), w(weight) {}

  const std::vector<PoseSample>& s;
  Mat3 C;
  double w;
  std::array<bool, kGeometryParams> free{};
  MatP JtJ;
  GeometryVec Jtr;
};

// Builds pb's normal equations at `at` (a fixed parameter's row and column
// those of the identity, its gradient zero); returns the cost there
double normal_equations(const GeometryVec& at, GeometryProblem* pb) {
  MatP& JtJ = pb->JtJ;
  GeometryVec& Jtr = pb->Jtr;
  JtJ.setZero();
  Jtr.setZero();
  double cost = 0;
  for (const PoseSample& p : pb->s) {
    const GeometryJacobian J = geometry_residual_jacobian(at, p, pb->C, pb->w);
    const GeometryResidual r = geometry_residual(at, p, pb->C, pb->w);
    JtJ.noalias() += J.transpose() * J;
    Jtr.noalias() += J.transpose() * r;
    cost += r.squaredNorm();
  }
  for (int k = 0; k < kGeometryParams; ++k) {
    if (pb->free[k]) continue;
    JtJ.row(k).setZero();
    JtJ.col(k).setZero();
    JtJ(k, k) = 1.0;
    Jtr[k] = 0.0;
  }
  return cost;
}

// the sum of squared residuals at `at`
double cost_at(const GeometryProblem& pb, const GeometryVec& at) {
  double c = 0;
  for (const PoseSample& p : pb.s)
    c += geometry_residual(at, p, pb.C, pb.w).squaredNorm();
  return c;
}

// One round of Levenberg-Marquardt (Marquardt's scaling) from *x, at most
// max_iterations steps, each counted in *iterations; it ends when a step
// gains less than 1e-10 of the cost or lambda passes 1e8
void geometry_lm_round(int max_iterations, GeometryProblem* pb, GeometryVec* x,
                       int* iterations) {
  double lambda = 1e-3;
  double cost = normal_equations(*x, pb);
  for (int it = 0; it < max_iterations; ++it) {
    ++*iterations;
    MatP A = pb->JtJ;
    A.diagonal() += lambda * pb->JtJ.diagonal().cwiseMax(1e-12);
    const GeometryVec dx = A.ldlt().solve(-pb->Jtr);
    const GeometryVec xn = *x + dx;
    const double cn = cost_at(*pb, xn);
    if (std::isfinite(cn) && cn < cost) {
      const double gain = (cost - cn) / std::max(cost, 1e-300);
      *x = xn;
      lambda = std::max(lambda / 3.0, 1e-9);
      cost = normal_equations(*x, pb);
      if (gain < 1e-10) break;
    } else {
      lambda *= 4.0;
      if (lambda > 1e8) break;
    }
  }
}

// Each parameter with its nominal (x0) and fitted (x) value, and its sigma
// from sigma^2 (J^T J)^-1 over the free parameters (pb's normal equations
// built at x)
std::vector<FittedParam> fitted_params(const GeometryProblem& pb,
                                       const GeometryVec& x0,
                                       const GeometryVec& x) {
  const double dof = 12.0 * static_cast<double>(pb.s.size()) - kGeometryParams;
  const double sigma2 = cost_at(pb, x) / dof;
  Eigen::FullPivLU<MatP> lu(pb.JtJ);
  const MatP cov = lu.isInvertible() ? MatP(sigma2 * lu.inverse())
                                     : MatP::Constant(std::nan(""));
  std::vector<FittedParam> out;
  for (int k = 0; k < kGeometryParams; ++k) {
    FittedParam p;
    p.name = geometry_param_name(k);
    p.unit = geometry_param_unit(k);
    p.nominal = x0[k];
    p.fitted = x[k];
    p.free = pb.free[k];
    p.sigma = pb.free[k] ? std::sqrt(std::max(cov(k, k), 0.0)) : 0.0;
    out.push_back(p);
  }
  return out;
}

}  // namespace

GeometryFit fit_geometry(const std::vector<PoseSample>& all,
                         const GeometryFitOptions& o) {
  check_pose_samples(all);
  const std::vector<PoseSample> s = spread_samples(all, o.max_samples);

  GeometryFit fit;
  fit.samples_used = s.size();
  const GeometryVec x0 = nominal_geometry();
  GeometryVec x = x0;
  GeometryProblem pb(s, estimate_convention(x, s),
                     o.rotation_weight_mm_per_rad);
  fit.convention_snapped = snap_to_signed_permutation(&pb.C);
  const Errors before = sample_errors(x, pb.C, s);
  fit.position_before_mm = error_stats(before.position_mm);
  fit.rotation_before_deg = error_stats(before.rotation_deg);

  pb.free.fill(true);
  // two rounds: the convention C re-estimated once the geometry has moved
  for (int round = 0; round < 2; ++round) {
    if (round > 0) {
      pb.C = estimate_convention(x, s);
      fit.convention_snapped = snap_to_signed_permutation(&pb.C);
    }
    pb.free[kOffsetT1 + 5] = fit.convention_snapped;
    if (!pb.free[kOffsetT1 + 5]) x[kOffsetT1 + 5] = 0.0;
    geometry_lm_round(o.max_iterations, &pb, &x, &fit.iterations);
  }
  normal_equations(x, &pb);

  fit.x = x;
  fit.convention = pb.C;
  const Errors after = sample_errors(x, pb.C, s);
  fit.position_after_mm = error_stats(after.position_mm);
  fit.rotation_after_deg = error_stats(after.rotation_deg);
  fit.params = fitted_params(pb, x0, x);
  fit.plausible = plausible(x);
  fit.explains = fit.plausible &&
                 fit.position_after_mm.p95 <= o.position_threshold_mm &&
                 fit.rotation_after_deg.p95 <= o.rotation_threshold_deg;
  return fit;
}

}  // namespace vmh::bringup
