#include "controller/control_law.h"

#include <Eigen/Cholesky>
// GCC 12 reports Eigen's tridiagonalisation of a fixed-capacity matrix as
// "may be used uninitialized"; a false positive inside Eigen (the storage is
// written before it is read), silenced here only
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace vmh {
namespace {

using SmallSquare = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic,
                                  Eigen::ColMajor, kMaxVmDof, kMaxVmDof>;

}  // namespace

void active_columns(const VmJacobian& J, JointMask locked, VmJacobian* out) {
  int n = 0;
  for (int j = 0; j < J.cols(); ++j) {
    if ((locked & (JointMask{1} << j)) == 0) ++n;
  }
  out->resize(6, n);
  int k = 0;
  for (int j = 0; j < J.cols(); ++j) {
    if ((locked & (JointMask{1} << j)) == 0) out->col(k++) = J.col(j);
  }
}

namespace {
// placement_residual from the pose at theta
Vec6 residual_of_pose(const VirtualMechanism& vm, const RmPose& rm,
                      const VmPose& pose) {
  Vec6 r;
  r.head<3>() = rm.p - pose.p;
  r.tail<3>() = -vm.geometric_orientation_error(pose, rm, nullptr);
  return r;
}
}  // namespace

Vec6 placement_residual(const VirtualMechanism& vm, const RmPose& rm,
                        const VmAngles& theta) {
  return residual_of_pose(vm, rm, vm.pose(theta));
}

namespace {
double weighted_cost(const Vec6& r, const Vec6& w) {
  return r.dot(w.cwiseProduct(r));
}

bool weighs_orientation(const Vec6& w) {
  return (w.tail<3>().array() != 0.0).any();
}

// placement_residual with the orientation rows left at zero where W does not
// weigh them: they would add exactly 0 to r^T W r and to J^T W r (the
// geometric error is finite for finite input), and their atan2 is most of a
// residual's cost under W_p
Vec6 weighted_residual_of_position(const RmPose& rm, const Vec3& p) {
  Vec6 r;
  r.head<3>() = rm.p - p;
  r.tail<3>().setZero();
  return r;
}
Vec6 weighted_residual(const VirtualMechanism& vm, const RmPose& rm,
                       const VmAngles& theta, bool orientation) {
  if (orientation) return placement_residual(vm, rm, theta);
  return weighted_residual_of_position(rm, vm.position(theta));
}
}  // namespace

namespace {

// The residual at the start: from the caller's pose where given, else from
// *theta's
Vec6 start_residual(const VirtualMechanism& vm, const RmPose& rm,
                    const VmAngles& theta, bool orientation,
                    const VmPose* pose_at_start) {
  if (pose_at_start != nullptr) {
    return orientation ? residual_of_pose(vm, rm, *pose_at_start)
                       : weighted_residual_of_position(rm, pose_at_start->p);
  }
  return weighted_residual(vm, rm, theta, orientation);
}

// The linear model at theta: the residual's Jacobian J, -J_V with the
// angular rows carried through the derivative of the rotation-vector
// error, which differs from the identity once the axes are far apart
// (under W_p the angular rows meet only zero weights and zero residual
// rows, so Me is not needed there); then the normal equations of eq. 3.15
// over its m active columns, padded to M with zero columns: A = Ja^T W Ja
// and grad = Ja^T W r. `pose` and `J_V`: the caller's X_V and J_V at
// theta, or nullptr (both): computed.
template <int M>
void linearise(const VirtualMechanism& vm, const RmPose& rm,
               const VmAngles& theta, const Vec6& w, bool orientation,
               const Vec6& r, const int* active, int m, const VmPose* pose,
               const VmJacobian* J_V, Eigen::Matrix<double, M, M>* A,
               Eigen::Matrix<double, M, 1>* grad) {
  VmJacobian J;
  if (J_V != nullptr) {
    J = *J_V;
    if (orientation) {
      const Mat3 Me = vm.orientation_error_jacobian(*pose, rm);
      J.bottomRows<3>() = (Me * J.bottomRows<3>()).eval();
    }
  } else if (orientation) {
    VmPose at;
    vm.pose_jacobian(theta, &at, &J);
    const Mat3 Me = vm.orientation_error_jacobian(at, rm);
    J.bottomRows<3>() = (Me * J.bottomRows<3>()).eval();
  } else {
    vm.jacobian(theta, &J);
  }
  const auto W = w.asDiagonal();
  Eigen::Matrix<double, 6, M> Ja;
  for (int k = 0; k < m; ++k) Ja.col(k) = J.col(active[k]);
  for (int k = m; k < M; ++k) Ja.col(k).setZero();
  A->noalias() = Ja.transpose() * W * Ja;
  grad->noalias() = Ja.transpose() * (W * r);
}

// The step solving (A + mu diag(A)) step = grad, with the columns scaled to
// unit diagonal: the surface mixes prismatic (1) and revolute (L) columns,
// and unscaled its J^T W J is conditioned ~1/(1 + L^2)^2, which leaves the
// steps at rounding noise above the tolerance. A joint that W cannot see
// (the twist under the geometric residual, every orientation joint under
// W_p) gets no step: it stays where it is
template <int M>
Eigen::Matrix<double, M, 1> damped_step(const Eigen::Matrix<double, M, M>& A,
                                        const Eigen::Matrix<double, M, 1>& grad,
                                        int m, double mu) {
  Eigen::Matrix<double, M, M> A_damped;
  Eigen::Matrix<double, M, 1> scale;
  const double mean_diag = A.diagonal().sum() / m + 1e-300;
  for (int i = 0; i < M; ++i) {
    scale[i] = A(i, i) > 1e-12 * mean_diag ? 1.0 / std::sqrt(A(i, i)) : 0.0;
  }
  A_damped = scale.asDiagonal() * A * scale.asDiagonal();
  for (int i = 0; i < M; ++i) {
    A_damped(i, i) = scale[i] > 0.0 ? A_damped(i, i) * (1.0 + mu) : 1.0;
  }
  return scale.cwiseProduct(
      A_damped.ldlt().solve(scale.cwiseProduct(grad)).eval());
}

// Levenberg-Marquardt's damping mu (relative to diag(A)) with Nielsen's
// update: after a step the cost took, with rho its actual over its
// predicted decrease, mu shrinks by up to 3 (never below `floor`); after a
// step refused it grows by nu, which doubles at each refusal in a row
struct Damping {
  double mu;
  double nu = 2.0;

  void taken(double rho, double floor) {
    const double t = 2.0 * std::clamp(rho, 0.0, 1.0) - 1.0;
    mu *= std::max(1.0 / 3.0, 1.0 - t * t * t);
    mu = std::max(mu, floor);
    nu = 2.0;
  }
  void refused() {
    mu *= nu;
    nu *= 2.0;
  }
};

// Gauss-Newton over the m active (unlocked) joints, whose indices into
// theta are active[0..m), in fixed-size M x M matrices, M >= m:
// the tick calls it with m = 1 (circle), 3 (sphere) or 3 and 5 (surface,
// held or sliding), and perf put Eigen's dynamic-size LDLT, its triangular
// solves and the resizes at a fifth of the sphere's Gauss-Newton tick.
// The other counts (a VM with joints locked) take the next size up: the
// padding columns of J are zero, so their joints are ones W cannot see
// (damped_step), their step is 0 and the active block's solve is the same.
// Each size is compiled once, and the compile is most of this file's.
template <int M>
PlacementResult gauss_newton_active(const VirtualMechanism& vm,
                                    const RmPose& rm,
                                    const PlacementOptions& options,
                                    const int* active, int m, VmAngles* theta,
                                    const VmPose* pose_at_start,
                                    const VmJacobian* J_at_start) {
  PlacementResult result;
  const Vec6& w = options.weights;
  Eigen::Matrix<double, M, M> A;
  Eigen::Matrix<double, M, 1> grad, step;
  VmAngles trial;
  const bool orientation = weighs_orientation(w);
  const bool given = pose_at_start != nullptr && J_at_start != nullptr;
  Vec6 r = start_residual(vm, rm, *theta, orientation,
                          given ? pose_at_start : nullptr);
  double cost = weighted_cost(r, w);
  Damping damping{options.relative_damping};
  bool fresh = true;  // J, A and grad belong to the current theta
  for (int it = 0; it < options.max_iterations; ++it) {
    if (fresh) {
      const bool at_start = it == 0 && given;
      linearise<M>(vm, rm, *theta, w, orientation, r, active, m,
                   at_start ? pose_at_start : nullptr,
                   at_start ? J_at_start : nullptr, &A, &grad);
      fresh = false;
    }
    step = damped_step<M>(A, grad, m, damping.mu);
    result.iterations = it + 1;
    if (!step.allFinite()) break;
    trial = *theta;
    for (int k = 0; k < m; ++k) trial[active[k]] += step[k];
    vm.normalize(&trial);
    // a step below the angles' ulp leaves them as they were (the usual case
    // from the closed form's answer, where the step is ~1e-17 rad): the
    // residual is the one in hand
    const Vec6 r_trial = trial == *theta
                             ? r
                             : weighted_residual(vm, rm, trial, orientation);
    const double cost_trial = weighted_cost(r_trial, w);
    // predicted decrease of r^T W r for the linearised residual
    const double predicted = step.dot(2.0 * grad - A * step);
    const double actual = cost - cost_trial;
    const double step_size = step.cwiseAbs().maxCoeff();
    const bool small_step = step_size < options.tolerance;
    // Below 1e-6 the linear model is far more accurate than the cost can
    // resolve (a step of d changes the cost by ~d^2 times its curvature,
    // under its rounding for d ~ 1e-8 far from the path), so such steps are
    // taken on the model's word.
    const bool local = step_size < 1e-6 && predicted > 0.0;
    if ((actual >= 0.0 && predicted > 0.0) || local) {
      *theta = trial;
      r = r_trial;
      cost = cost_trial;
      fresh = true;
      damping.taken(actual / predicted, options.relative_damping);
      if (small_step) {
        result.converged = true;
        break;
      }
    } else {
      if (small_step || !(predicted > 0.0)) {
        // no descent left along any damped step: a minimum to precision
        result.converged = true;
        break;
      }
      damping.refused();
    }
  }
  result.cost = cost;
  return result;
}

}  // namespace

PlacementResult place_gauss_newton(const VirtualMechanism& vm,
                                   const RmPose& rm,
                                   const PlacementOptions& options,
                                   JointMask locked, VmAngles* theta,
                                   const VmPose* pose_at_start,
                                   const VmJacobian* J_at_start) {
  // Gauss-Newton with Levenberg-Marquardt damping (Nielsen's update): near
  // a small-residual solution the damping shrinks and the steps are eq. 3.15
  // itself; where Gauss-Newton overshoots (a point beyond 2L from a circle's
  // pivot, where the plain iteration diverges at rate |1 - d/L|, or a
  // surface probe stretched toward an RM it cannot reach) the damping grows
  // and the step turns toward steepest descent.
  // the active (unlocked) joints' indices into theta
  static_assert(kMaxVmDof == 5, "the sizes below cover 1..kMaxVmDof joints");
  int active[kMaxVmDof];
  int m = 0;
  for (int j = 0; j < vm.dof(); ++j) {
    if ((locked & (JointMask{1} << j)) == 0) active[m++] = j;
  }
  switch (m) {
    case 1:
      return gauss_newton_active<1>(vm, rm, options, active, m, theta,
                                    pose_at_start, J_at_start);
    case 2:
    case 3:
      return gauss_newton_active<3>(vm, rm, options, active, m, theta,
                                    pose_at_start, J_at_start);
    case 4:
    case 5:
      return gauss_newton_active<5>(vm, rm, options, active, m, theta,
                                    pose_at_start, J_at_start);
    default: {
      // every joint locked: nothing to move
      PlacementResult result;
      result.converged = true;
      result.cost =
          weighted_cost(weighted_residual(vm, rm, *theta,
                                          weighs_orientation(options.weights)),
                        options.weights);
      return result;
    }
  }
}

namespace {

// From the ascending eigenvalues s[0..n) of J^T W_A J: rcond and the flag
// into *result, and each eigenvalue inverted as s / (s^2 + rho^2),
// rho = damping * s_max, into *inv_s (0 where that is 0 / 0)
template <class Values, class Inverses>
void regularise(const Values& s, int n, double singular_rcond, double damping,
                ProjectionResult* result, Inverses* inv_s) {
  const double s_max = std::max(s[n - 1], 0.0);
  const double s_min = std::max(s[0], 0.0);
  result->rcond = s_max > 0.0 ? s_min / s_max : 0.0;
  result->singular = !(result->rcond >= singular_rcond);
  const double rho = damping * s_max;
  for (int i = 0; i < n; ++i) {
    const double si = std::max(s[i], 0.0);
    const double den = si * si + rho * rho;
    (*inv_s)[i] = den > 0.0 ? si / den : 0.0;
  }
}

// One column (the circle): J^T W_A J is a scalar, its own eigenvalue with
// eigenvector 1; the same regularised inverse without the solver
ProjectionResult project_one_column(const VmJacobian& J, const Vec6& W_A,
                                    const Vec6& g, double singular_rcond,
                                    double damping, Vec6* f) {
  ProjectionResult result;
  const auto j = J.col(0);
  const double s = j.dot(W_A.cwiseProduct(j));
  const double s_max = std::max(s, 0.0);
  result.rcond = s_max > 0.0 ? 1.0 : 0.0;
  result.singular = !(result.rcond >= singular_rcond);
  const double rho = damping * s_max;
  const double den = s_max * s_max + rho * rho;
  const double inv_s = den > 0.0 ? s_max / den : 0.0;
  *f = g - W_A.cwiseProduct(j) * (inv_s * j.dot(g));
  return result;
}

// Three columns, where A = J3^T W_A J3 is far enough from singular: the
// eigenvalues alone in closed form give rcond; where the damping changes no
// 1/s by more than 1e-16 relative (rho <= 1e-8 s_min, so (rho/s)^2 <=
// 1e-16), the regularised inverse is A^-1 to rounding and a Cholesky solve
// gives it. False, nothing written, where the eigenvectors are needed
bool project_three_by_cholesky(const Eigen::Matrix<double, 6, 3>& J3,
                               const Mat3& A, const Vec6& W_A, const Vec6& g,
                               double singular_rcond, double damping, Vec6* f,
                               ProjectionResult* result) {
  Eigen::SelfAdjointEigenSolver<Mat3> values;
  values.computeDirect(A, Eigen::EigenvaluesOnly);
  const Vec3& sv = values.eigenvalues();  // ascending
  const double sv_max = std::max(sv[2], 0.0);
  const double sv_min = std::max(sv[0], 0.0);
  if (!(sv_max > 0.0 && damping * sv_max <= 1e-8 * sv_min)) return false;
  const Eigen::LLT<Mat3> llt(A);
  if (llt.info() != Eigen::Success) return false;
  result->rcond = sv_min / sv_max;
  result->singular = !(result->rcond >= singular_rcond);
  const Vec3 z = llt.solve(J3.transpose() * g);
  *f = g - W_A.asDiagonal() * (J3 * z);
  return true;
}

// Three columns (the sphere): the same steps on fixed-size 3 x 3 matrices,
// which Eigen tridiagonalises in closed form instead of by Householder
// reflections
ProjectionResult project_three_columns(const VmJacobian& J, const Vec6& W_A,
                                       const Vec6& g, double singular_rcond,
                                       double damping, Vec6* f) {
  ProjectionResult result;
  const auto WA = W_A.asDiagonal();
  const Eigen::Matrix<double, 6, 3> J3 = J;
  const Mat3 A = J3.transpose() * WA * J3;
  if (project_three_by_cholesky(J3, A, W_A, g, singular_rcond, damping, f,
                                &result)) {
    return result;
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig(A);
  Vec3 inv_s;
  regularise(eig.eigenvalues(), 3, singular_rcond, damping, &result, &inv_s);
  const Vec3 x = J3.transpose() * g;
  const Vec3 y = (eig.eigenvectors().transpose() * x).cwiseProduct(inv_s);
  const Vec3 z = eig.eigenvectors() * y;
  *f = g - WA * (J3 * z);
  return result;
}

// Any number of columns, and the projector where asked for: by the
// eigendecomposition of A = J^T W_A J, symmetric positive semi-definite
// and at most 5 x 5
ProjectionResult project_any_columns(const VmJacobian& J, const Vec6& W_A,
                                     const Vec6& g, double singular_rcond,
                                     double damping, Vec6* f, Mat6* projector) {
  ProjectionResult result;
  const int m = static_cast<int>(J.cols());
  const auto WA = W_A.asDiagonal();
  SmallSquare A;
  A.noalias() = J.transpose() * WA * J;
  Eigen::SelfAdjointEigenSolver<SmallSquare> eig(A);
  VmAngles inv_s(m);
  regularise(eig.eigenvalues(), m, singular_rcond, damping, &result, &inv_s);
  // J^T g, into the eigenbasis, scaled, and back: x = A^+ J^T g
  VmAngles x = J.transpose() * g;
  VmAngles y = eig.eigenvectors().transpose() * x;
  y = y.cwiseProduct(inv_s);
  x.noalias() = eig.eigenvectors() * y;
  *f = g - WA * (J * x);
  if (projector != nullptr) {
    SmallSquare A_inv = eig.eigenvectors() * inv_s.asDiagonal() *
                        eig.eigenvectors().transpose();
    *projector = Mat6::Identity() - WA * J * A_inv * J.transpose();
  }
  return result;
}

}  // namespace

ProjectionResult project_motion_force(const VmJacobian& J, const Vec6& W_A,
                                      const Vec6& g, double singular_rcond,
                                      double damping, Vec6* f,
                                      Mat6* projector) {
  const int m = static_cast<int>(J.cols());
  if (m == 0) {
    *f = g;
    if (projector != nullptr) projector->setIdentity();
    return ProjectionResult();
  }
  if (m == 1 && projector == nullptr) {
    return project_one_column(J, W_A, g, singular_rcond, damping, f);
  }
  if (m == 3 && projector == nullptr) {
    return project_three_columns(J, W_A, g, singular_rcond, damping, f);
  }
  return project_any_columns(J, W_A, g, singular_rcond, damping, f, projector);
}

ProjectionResult project_motion_force_sphere(const VmJacobian& J,
                                             double length, double sin_polar,
                                             double cos_polar, const Vec6& W_A,
                                             const Vec6& g,
                                             double singular_rcond,
                                             double damping, Vec6* f) {
  const double a = W_A[0], b = W_A[3];
  const bool block_uniform = J.cols() == 3 && W_A[1] == a && W_A[2] == a &&
                             W_A[4] == b && W_A[5] == b;
  if (block_uniform) {
    // J^T W_A J = [p 0 q; 0 m 0; q 0 r] (see the header)
    const double aLL = a * length * length;
    const double p = aLL * sin_polar * sin_polar + b;
    const double m = aLL + b;
    const double q = -b * cos_polar;
    const double r = b;
    // the 2 x 2 block's eigenvalues: the larger from the trace and the
    // discriminant, the smaller as det / larger (no cancellation)
    const double half_diff = 0.5 * (p - r);
    const double big = 0.5 * (p + r) + std::sqrt(half_diff * half_diff + q * q);
    const double det = p * r - q * q;
    const double small = det / big;
    const double s_max = std::max(big, m);
    const double s_min = std::max(std::min(small, m), 0.0);
    if (s_max > 0.0 && det > 0.0 && damping * s_max <= 1e-8 * s_min) {
      ProjectionResult result;
      result.rcond = s_min / s_max;
      result.singular = !(result.rcond >= singular_rcond);
      const Eigen::Matrix<double, 6, 3> J3 = J;
      const Vec3 x = J3.transpose() * g;
      const double inv_det = 1.0 / det;
      const Vec3 z((r * x[0] - q * x[2]) * inv_det, x[1] / m,
                   (p * x[2] - q * x[0]) * inv_det);
      *f = g - W_A.asDiagonal() * (J3 * z);
      return result;
    }
  }
  return project_motion_force(J, W_A, g, singular_rcond, damping, f);
}

}  // namespace vmh

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
