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

Vec6 placement_residual(const VirtualMechanism& vm, const RmPose& rm,
                        const VmAngles& theta) {
  const VmPose pose = vm.pose(theta);
  Vec6 r;
  r.head<3>() = rm.p - pose.p;
  r.tail<3>() = -vm.geometric_orientation_error(pose, rm, nullptr);
  return r;
}

namespace {
double weighted_cost(const Vec6& r, const Vec6& w) {
  return r.dot(w.cwiseProduct(r));
}
}  // namespace

PlacementResult place_gauss_newton(const VirtualMechanism& vm,
                                   const RmPose& rm,
                                   const PlacementOptions& options,
                                   JointMask locked, VmAngles* theta) {
  PlacementResult result;
  const Vec6& w = options.weights;
  const auto W = w.asDiagonal();
  VmJacobian J, Ja;
  SmallSquare A;
  VmAngles step, full_step, trial;
  Vec6 r = placement_residual(vm, rm, *theta);
  double cost = weighted_cost(r, w);
  for (int it = 0; it < options.max_iterations; ++it) {
    vm.jacobian(*theta, &J);
    active_columns(J, locked, &Ja);
    const int m = static_cast<int>(Ja.cols());
    if (m == 0) {
      result.converged = true;
      break;
    }
    A.noalias() = Ja.transpose() * W * Ja;
    const double mean_diag = A.diagonal().sum() / m;
    const double lambda = options.relative_damping * mean_diag + 1e-300;
    A.diagonal().array() += lambda;
    step.noalias() = Ja.transpose() * (W * r);
    A.ldlt().solveInPlace(step);
    result.iterations = it + 1;
    if (!step.allFinite()) break;
    // scatter the active step back onto the joints
    full_step = VmAngles::Zero(vm.dof());
    for (int j = 0, k = 0; j < vm.dof(); ++j) {
      if ((locked & (JointMask{1} << j)) == 0) full_step[j] = step[k++];
    }
    if (step.cwiseAbs().maxCoeff() < options.tolerance) {
      *theta += full_step;
      vm.normalize(theta);
      r = placement_residual(vm, rm, *theta);
      cost = weighted_cost(r, w);
      result.converged = true;
      break;
    }
    // Far from the path the Gauss-Newton step overshoots (its rate on a
    // circle is |1 - d/L| for a point at distance d from the pivot, so it
    // diverges beyond d = 2L): halve it until the cost goes down.
    bool descended = false;
    for (int halving = 0; halving < 30; ++halving) {
      trial = *theta + full_step;
      vm.normalize(&trial);
      const Vec6 r_trial = placement_residual(vm, rm, trial);
      const double cost_trial = weighted_cost(r_trial, w);
      if (cost_trial <= cost) {
        *theta = trial;
        r = r_trial;
        cost = cost_trial;
        descended = true;
        break;
      }
      full_step *= 0.5;
    }
    if (!descended) {
      // no step lowers the cost: a minimum to working precision
      result.converged = true;
      break;
    }
  }
  result.cost = cost;
  return result;
}

ProjectionResult project_motion_force(const VmJacobian& J, const Vec6& W_A,
                                      const Vec6& g, double singular_rcond,
                                      double damping, Vec6* f,
                                      Mat6* projector) {
  ProjectionResult result;
  const int m = static_cast<int>(J.cols());
  if (m == 0) {
    *f = g;
    if (projector != nullptr) projector->setIdentity();
    return result;
  }
  const auto WA = W_A.asDiagonal();
  SmallSquare A;
  A.noalias() = J.transpose() * WA * J;
  // A is symmetric positive semi-definite and at most 5 x 5
  Eigen::SelfAdjointEigenSolver<SmallSquare> eig(A);
  const auto& s = eig.eigenvalues();  // ascending
  const double s_max = std::max(s[m - 1], 0.0);
  const double s_min = std::max(s[0], 0.0);
  result.rcond = s_max > 0.0 ? s_min / s_max : 0.0;
  result.singular = !(result.rcond >= singular_rcond);
  const double rho = damping * s_max;
  VmAngles inv_s(m);
  for (int i = 0; i < m; ++i) {
    const double si = std::max(s[i], 0.0);
    const double den = si * si + rho * rho;
    inv_s[i] = den > 0.0 ? si / den : 0.0;
  }
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

}  // namespace vmh

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
