// The pieces of the virtual-mechanism control law, as free functions so that
// each can be tested on its own: VM placement by weighted Gauss-Newton
// (eq. 3.14-3.16) and the motion-force projection (eq. 3.11 with Appendix D's
// weight W_A).
//
// All vectors are in the device frame and in the caller's length unit
// (rows 0-2) and rad (rows 3-5). Nothing here allocates or throws.
#ifndef VMHAPTICS_CONTROLLER_CONTROL_LAW_H_
#define VMHAPTICS_CONTROLLER_CONTROL_LAW_H_

#include <cstdint>

#include "controller/virtual_mechanism.h"

namespace vmh {

// Copies the columns of J whose bit in `locked` is clear into *out.
void active_columns(const VmJacobian& J, JointMask locked, VmJacobian* out);

// ------------------------------------------------------------- placement

struct PlacementOptions {
  // diagonal of W in eq. 3.15: (x, y, z, theta_x, theta_y, theta_z).
  // (1,1,1,0,0,0) is W_p (eq. 3.21: nearest point, the thesis's theta_V);
  // (0,0,0,1,1,1) is W_o (eq. 3.17: aligned with the stylus, theta_R).
  Vec6 weights = (Vec6() << 1, 1, 1, 0, 0, 0).finished();
  double tolerance = 1e-9;  // stop when max |delta theta| falls below this
  // Gauss-Newton converges only linearly where the VM cannot reach the RM
  // (rate about residual / L): the surface, warm-started near its plane,
  // takes 5-20 iterations and up to ~50 far from it; circle and sphere
  // under W_p start at the closed form and stop after one
  int max_iterations = 60;
  // Levenberg damping, relative to the mean diagonal of J^T W J; it keeps
  // joints that W does not see (the twist under W_p) where they are
  double relative_damping = 1e-12;
};

struct PlacementResult {
  int iterations = 0;
  bool converged = false;
  double cost = 0.0;  // r^T W r at the returned theta
};

// The placement residual r(theta) = X_R - X_V(theta): the position
// difference, and the rotation vector carrying the VM's link axis onto the
// stylus axis (minus the geometric orientation error). Gauss-Newton needs a
// residual whose derivative is J_V, so placement always uses this geometric
// form, whichever error formulation the force law uses (docs/control.md).
Vec6 placement_residual(const VirtualMechanism& vm, const RmPose& rm,
                        const VmAngles& theta);

// Iterates eq. 3.15/3.16, delta = (J^T W J)^-1 J^T W r, theta += delta,
// from *theta (the warm start) and leaves the result in *theta, normalised.
// The step carries Levenberg-Marquardt damping that adapts to how well the
// linear model predicted the cost (see control_law.cc). A caller that has
// X_V and J_V at the starting *theta already (the servo tick, from the
// closed form it starts from) passes them, and the first iteration uses them
// instead of computing them again; nullptr (both): computed.
PlacementResult place_gauss_newton(const VirtualMechanism& vm,
                                   const RmPose& rm,
                                   const PlacementOptions& options,
                                   JointMask locked, VmAngles* theta,
                                   const VmPose* pose_at_start = nullptr,
                                   const VmJacobian* J_at_start = nullptr);

// ------------------------------------------------------------- projection

struct ProjectionResult {
  // smallest over largest eigenvalue of J^T W_A J (1 for a 1-DOF VM)
  double rcond = 1.0;
  bool singular = false;  // rcond below the threshold: regularised
};

// f = (I - W_A J (J^T W_A J)^-1 J^T) g (eq. 3.11; Appendix D's W_A). The
// inverse is regularised: each eigenvalue s of J^T W_A J is inverted as
// s / (s^2 + rho^2) with rho = damping * s_max: 1/s to a relative
// (damping / rcond)^2 (1e-6 at the Controller's defaults wherever the result
// is not flagged singular), going smoothly to 0 as s does.
// `projector`, if given, receives the 6 x 6 matrix.
ProjectionResult project_motion_force(const VmJacobian& J, const Vec6& W_A,
                                      const Vec6& g, double singular_rcond,
                                      double damping, Vec6* f,
                                      Mat6* projector = nullptr);

// The same projection for the sphere (SphereVm's J, unlocked), using the
// structure of its J^T W_A J. For W_A = diag(a, a, a, b, b, b) (the thesis's
// identity among them) and any pivot orientation, eq. 3.31 gives, with
// s2, c2 the sine and cosine of the polar angle,
//   J^T W_A J = [a L^2 s2^2 + b, 0, -b c2; 0, a L^2 + b, 0; -b c2, 0, b],
// whose eigenvalues are a L^2 + b and those of the 2 x 2 block of joints 1
// and 3, all by square roots, and whose inverse is a 2 x 2 inverse and a
// division. Where that block is as far from singular as the general path's
// Cholesky branch asks (rho <= 1e-8 s_min), f is computed so; otherwise, and
// for any other W_A, it returns project_motion_force(J, ...). The same f as
// project_motion_force to rounding (J^T W_A J is formed from the angles
// instead of from J's entries).
ProjectionResult project_motion_force_sphere(const VmJacobian& J,
                                             double length, double sin_polar,
                                             double cos_polar, const Vec6& W_A,
                                             const Vec6& g,
                                             double singular_rcond,
                                             double damping, Vec6* f);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_CONTROL_LAW_H_
