// Checks of controller/control_law against routes that do not share its
// code: the projector's algebraic identities, the projection computed here
// on dynamic matrices with Eigen's full-pivot LU and an explicit inverse,
// range(J) from a Jacobi SVD of J, and the VMs' closed-form placements
// (nearest / aligned) and first-order optimality for Gauss-Newton.
#include "controller/control_law.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/virtual_mechanism.h"
#include "tests/support/random_vm.h"

namespace vmh {
namespace {

constexpr double kPi = 3.14159265358979323846;
// the Controller's defaults (ControllerParams::singular_rcond, _damping)
constexpr double kSingularRcond = 1e-10;
constexpr double kDamping = 1e-13;

using Eigen::MatrixXd;
using Eigen::VectorXd;

using testing::random_theta;
using testing::random_unit;
using testing::uniform;

// Gaussian 6 x m; full rank with probability one (checked by the SVD below)
VmJacobian random_jacobian(std::mt19937* rng, int m) {
  std::normal_distribution<double> n(0.0, 1.0);
  VmJacobian J(6, m);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < m; ++j) J(i, j) = n(*rng);
  return J;
}

Vec6 random_vec6(std::mt19937* rng, double scale) {
  Vec6 v;
  for (int i = 0; i < 6; ++i) v[i] = uniform(rng, -scale, scale);
  return v;
}

// positive diagonal W_A spanning two decades
Vec6 random_weights(std::mt19937* rng) {
  Vec6 w;
  for (int i = 0; i < 6; ++i) w[i] = std::pow(10.0, uniform(rng, -1.0, 1.0));
  return w;
}

// a dynamic copy: the checks' products run on plain dynamic matrices (GCC 12
// reports false "may be used uninitialized" warnings inside Eigen's
// reductions over products of the fixed-capacity VmJacobian)
MatrixXd X(const VmJacobian& J) { return J; }

int svd_rank(const MatrixXd& M, double rel) {
  Eigen::JacobiSVD<MatrixXd> svd(M);
  const VectorXd s = svd.singularValues();
  int r = 0;
  for (int i = 0; i < s.size(); ++i)
    if (s[i] > rel * s[0]) ++r;
  return r;
}

// the exact projector I - W J (J^T W J)^-1 J^T, on dynamic matrices with an
// explicit full-pivot-LU inverse
MatrixXd exact_projector(const VmJacobian& J_in, const Vec6& w) {
  const MatrixXd J = J_in;
  const MatrixXd W = w.asDiagonal();
  const MatrixXd A = J.transpose() * W * J;
  Eigen::FullPivLU<MatrixXd> lu(A);
  EXPECT_TRUE(lu.isInvertible());
  return MatrixXd::Identity(6, 6) - W * J * lu.inverse() * J.transpose();
}

// ------------------------------------------------------------- projection

// identity: for random full-rank J (6 x m, m = 1..5) and W_A = I or a random
// positive diagonal, P = P^2, J^T P = 0 (f does no work along any VM motion),
// P W_A J = 0, f = P g, rank P = trace P = 6 - m
TEST(ProjectMotionForce, ProjectorIdentities) {
  std::mt19937 rng(101);
  for (int m = 1; m <= kMaxVmDof; ++m) {
    for (int k = 0; k < 200; ++k) {
      const VmJacobian J = random_jacobian(&rng, m);
      ASSERT_EQ(svd_rank(J, 1e-6), m);
      const Vec6 w = k % 2 == 0 ? Vec6::Ones() : random_weights(&rng);
      const Vec6 g = random_vec6(&rng, 10.0);
      Vec6 f;
      Mat6 P;
      const ProjectionResult pr =
          project_motion_force(J, w, g, kSingularRcond, kDamping, &f, &P);
      EXPECT_FALSE(pr.singular);
      EXPECT_LE((P * P - P).norm(), 1e-10 * P.norm()) << "m " << m;
      EXPECT_LE((X(J).transpose() * P).norm(), 1e-10 * J.norm()) << "m " << m;
      EXPECT_LE((P * w.asDiagonal() * X(J)).norm(), 1e-10 * 10 * J.norm())
          << "m " << m;
      EXPECT_LE((f - P * g).norm(), 1e-12 * g.norm()) << "m " << m;
      // J^T f = 0: no power along any VM joint velocity
      EXPECT_LE((X(J).transpose() * f).norm(), 1e-10 * J.norm() * g.norm());
      EXPECT_EQ(svd_rank(P, 1e-8), 6 - m) << "m " << m;
      EXPECT_NEAR(P.trace(), 6.0 - m, 1e-10) << "m " << m;
    }
  }
}

// identity: with W_A = I, P is symmetric and equals I - J (J^T J)^-1 J^T
// computed here independently (full-pivot LU, explicit inverse)
TEST(ProjectMotionForce, IdentityWeightIsTheOrthogonalProjector) {
  std::mt19937 rng(102);
  for (int m = 1; m <= kMaxVmDof; ++m) {
    for (int k = 0; k < 200; ++k) {
      const VmJacobian J = random_jacobian(&rng, m);
      const Vec6 g = random_vec6(&rng, 10.0);
      Vec6 f;
      Mat6 P;
      project_motion_force(J, Vec6::Ones(), g, kSingularRcond, kDamping, &f,
                           &P);
      EXPECT_LE((P - P.transpose()).norm(), 1e-12) << "m " << m;
      const MatrixXd P_ref = exact_projector(J, Vec6::Ones());
      EXPECT_LE((MatrixXd(P) - P_ref).norm(), 1e-10) << "m " << m;
      EXPECT_LE((VectorXd(f) - P_ref * VectorXd(g)).norm(), 1e-9 * g.norm());
    }
  }
}

// the projection f = g - W J x, x = argmin |W^(-1/2) (g - W J x)|, by a
// column-pivoted Householder QR of W^(1/2) J: no normal equations, so its
// accuracy does not depend on the square of J's conditioning
VectorXd qr_projection(const VmJacobian& J, const Vec6& w, const Vec6& g) {
  const MatrixXd B = w.cwiseSqrt().asDiagonal() * X(J);
  const VectorXd h = w.cwiseSqrt().cwiseInverse().asDiagonal() * VectorXd(g);
  const VectorXd x = B.colPivHouseholderQr().solve(h);
  return VectorXd(g) - w.asDiagonal() * (X(J) * x);
}

// random angles of each VM away from its poles
void vm_jacobians(double L, int count, std::mt19937* rng,
                  std::vector<VmJacobian>* out, bool with_surface) {
  const CircleVm circle(VmMount{}, L);
  const SphereVm sphere(VmMount{}, L);
  const SurfaceVm surface(VmMount{}, L);
  for (int k = 0; k < count; ++k) {
    VmAngles t1(1), t3(3), t5(5);
    t1 << uniform(rng, -kPi, kPi);
    t3 << uniform(rng, -kPi, kPi), uniform(rng, 0.3, kPi - 0.3),
        uniform(rng, -kPi, kPi);
    t5 << uniform(rng, -L, L), uniform(rng, -L, L), uniform(rng, -kPi, kPi),
        uniform(rng, 0.3, kPi - 0.3), uniform(rng, -kPi, kPi);
    VmJacobian J;
    circle.jacobian(t1, &J);
    out->push_back(J);
    sphere.jacobian(t3, &J);
    out->push_back(J);
    if (with_surface) {
      surface.jacobian(t5, &J);
      out->push_back(J);
    }
  }
}

// identity: well-conditioned J (Gaussian, and the VMs' own Jacobians at
// L = 1, plus the circle and sphere at L = 50, rcond ~ 1/(1 + L^2)),
// weighted or not: not singular, and f equals the exact projection (full-
// pivot LU inverse, and QR) to 1e-9 relative
TEST(ProjectMotionForce, WellConditionedMatchesExactProjection) {
  std::mt19937 rng(103);
  std::vector<VmJacobian> Js;
  for (int m = 1; m <= kMaxVmDof; ++m)
    for (int k = 0; k < 50; ++k) Js.push_back(random_jacobian(&rng, m));
  vm_jacobians(1.0, 50, &rng, &Js, true);
  vm_jacobians(50.0, 50, &rng, &Js, false);
  for (const VmJacobian& J : Js) {
    for (int weighted = 0; weighted < 2; ++weighted) {
      const Vec6 w = weighted ? random_weights(&rng) : Vec6::Ones();
      Vec6 g = random_vec6(&rng, 10.0);
      g.tail<3>() *= 50.0;  // torques in N x mm
      Vec6 f;
      const ProjectionResult pr =
          project_motion_force(J, w, g, kSingularRcond, kDamping, &f);
      EXPECT_FALSE(pr.singular) << "rcond " << pr.rcond;
      EXPECT_GE(pr.rcond, kSingularRcond);
      EXPECT_LE(pr.rcond, 1.0);
      const VectorXd f_lu = exact_projector(J, w) * VectorXd(g);
      const VectorXd f_qr = qr_projection(J, w, g);
      EXPECT_LE((f_lu - f_qr).norm(), 1e-10 * g.norm());  // the references
      EXPECT_LE((VectorXd(f) - f_qr).norm(), 1e-9 * g.norm())
          << "m " << J.cols() << " rcond " << pr.rcond;
    }
  }
}

// The surface in mm (L = 50) is far from isotropic: rcond of J^T W_A J goes
// down to ~1e-9 with a non-uniform W_A, still "not singular" at the
// Controller's threshold. Eigen-decomposing J^T W_A J resolves its smallest
// eigenvalue only to eps * s_max, so f is good to about eps / rcond
// relative (~1e-7 here), not to 1e-9; the QR reference is good to ~1e-12.
// bound: |f - f_exact| <= 100 eps / rcond |g| (observed <= ~5 eps / rcond)
TEST(ProjectMotionForce, BadlyScaledSurfaceAccurateToEpsOverRcond) {
  std::mt19937 rng(109);
  const SurfaceVm surface(VmMount{}, 50.0);
  const double eps = std::numeric_limits<double>::epsilon();
  double worst_ratio = 0;
  for (int k = 0; k < 1000; ++k) {
    VmAngles t(5);
    t << uniform(&rng, -50, 50), uniform(&rng, -50, 50),
        uniform(&rng, -kPi, kPi), uniform(&rng, 0.3, kPi - 0.3),
        uniform(&rng, -kPi, kPi);
    VmJacobian J;
    surface.jacobian(t, &J);
    const Vec6 w = k % 2 ? random_weights(&rng) : Vec6::Ones();
    Vec6 g = random_vec6(&rng, 10.0);
    g.tail<3>() *= 50.0;
    Vec6 f;
    const ProjectionResult pr =
        project_motion_force(J, w, g, kSingularRcond, kDamping, &f);
    ASSERT_FALSE(pr.singular);
    const double err = (VectorXd(f) - qr_projection(J, w, g)).norm() / g.norm();
    EXPECT_LE(err, 100 * eps / pr.rcond + 1e-13) << "rcond " << pr.rcond;
    worst_ratio = std::max(worst_ratio, err / (eps / pr.rcond));
  }
  RecordProperty("worst_error_over_eps_per_rcond", std::to_string(worst_ratio));
}

// identity: rcond is the smallest over the largest eigenvalue of J^T W_A J,
// here computed from the singular values of W_A^(1/2) J
TEST(ProjectMotionForce, RcondIsTheEigenvalueRatio) {
  std::mt19937 rng(104);
  for (int m = 1; m <= kMaxVmDof; ++m) {
    for (int k = 0; k < 50; ++k) {
      const VmJacobian J = random_jacobian(&rng, m);
      const Vec6 w = random_weights(&rng);
      Vec6 f;
      const ProjectionResult pr = project_motion_force(
          J, w, Vec6::Ones(), kSingularRcond, kDamping, &f);
      const MatrixXd B = w.cwiseSqrt().asDiagonal() * MatrixXd(J);
      Eigen::JacobiSVD<MatrixXd> svd(B);
      const VectorXd s = svd.singularValues();
      const double expected = std::pow(s[m - 1] / s[0], 2);
      EXPECT_NEAR(pr.rcond, expected, 1e-10 + 1e-8 * expected) << "m " << m;
    }
  }
}

// "J_V^T W_A P = 0", read literally, is NOT an identity for W_A != I:
// J^T W P = J^T W - (J^T W W J)(J^T W J)^-1 J^T, and W W != W unless W is
// a projector (W = I). What does hold for every W_A is J^T P = 0 (the
// force does no work along the VM) and P W_A J = 0. This test shows the
// literal form failing for a non-identity W_A and holding for W_A = I.
TEST(ProjectMotionForce, JTransposeWPIsNotZeroForNonIdentityWeight) {
  std::mt19937 rng(105);
  const VmJacobian J = random_jacobian(&rng, 3);
  Vec6 w;
  w << 1.0, 1.0, 1.0, 5.0, 0.2, 3.0;
  Vec6 f;
  Mat6 P;
  project_motion_force(J, w, Vec6::Ones(), kSingularRcond, kDamping, &f, &P);
  const double scale = J.norm() * P.norm();
  EXPECT_LE((X(J).transpose() * P).norm(), 1e-12 * scale);
  EXPECT_GT((X(J).transpose() * w.asDiagonal() * P).norm(), 1e-2 * scale);
  // and the same expression vanishes for W_A = I
  project_motion_force(J, Vec6::Ones(), Vec6::Ones(), kSingularRcond, kDamping,
                       &f, &P);
  EXPECT_LE((X(J).transpose() * P).norm(), 1e-12 * J.norm() * P.norm());
}

// the three rank-deficient Jacobians of the brief
std::vector<std::pair<std::string, VmJacobian>> rank_deficient() {
  std::mt19937 rng(106);
  std::vector<std::pair<std::string, VmJacobian>> out;
  VmJacobian J = random_jacobian(&rng, 4);
  J.col(3) = J.col(1);
  out.emplace_back("two equal columns", J);
  J = random_jacobian(&rng, 3);
  J.col(0).setZero();
  out.emplace_back("a zero column", J);
  for (double L : {50.0, 0.05}) {
    const SphereVm sphere(VmMount{}, L);
    VmAngles t(3);
    t << 0.7, 0.0, -0.4;  // the -z pole: azimuth and twist both about z
    sphere.jacobian(t, &J);
    out.emplace_back("sphere at theta2 = 0, L " + std::to_string(L), J);
  }
  return out;
}

// identity: a rank-deficient J gives a finite result flagged singular, rcond
// below the threshold; P still annihilates range(J) and leaves its
// orthogonal complement (from the SVD of J) unchanged, W_A = I
TEST(ProjectMotionForce, RankDeficientIsFiniteAndStillProjects) {
  std::mt19937 rng(107);
  for (const auto& [name, J] : rank_deficient()) {
    const MatrixXd Jd = J;
    const int r = svd_rank(Jd, 1e-10);
    ASSERT_LT(r, J.cols()) << name;
    Eigen::JacobiSVD<MatrixXd> svd(Jd, Eigen::ComputeFullU);
    const MatrixXd U = svd.matrixU();
    for (int k = 0; k < 20; ++k) {
      const Vec6 g = random_vec6(&rng, 10.0);
      Vec6 f;
      Mat6 P;
      const ProjectionResult pr = project_motion_force(
          J, Vec6::Ones(), g, kSingularRcond, kDamping, &f, &P);
      EXPECT_TRUE(f.allFinite()) << name;
      EXPECT_TRUE(P.allFinite()) << name;
      EXPECT_TRUE(pr.singular) << name;
      EXPECT_LT(pr.rcond, kSingularRcond) << name;
      // range(J): P J = 0
      EXPECT_LE((P * X(J)).norm(), 1e-6 * J.norm()) << name;
      // orthogonal complement of range(J): untouched
      for (int i = r; i < 6; ++i) {
        const Vec6 v = U.col(i);
        EXPECT_LE((P * v - v).norm(), 1e-6) << name;
      }
      // f is g without its part in range(J)
      const MatrixXd Ur = U.leftCols(r);
      const VectorXd f_ref = VectorXd(g) - Ur * (Ur.transpose() * VectorXd(g));
      EXPECT_LE((VectorXd(f) - f_ref).norm(), 1e-6 * g.norm()) << name;
      EXPECT_LE((X(J).transpose() * f).norm(), 1e-6 * J.norm() * g.norm())
          << name;
    }
  }
}

// identity: a VM with no free joint (all locked) leaves g as it is
TEST(ProjectMotionForce, NoColumnsIsIdentity) {
  const VmJacobian J(6, 0);
  Vec6 g;
  g << 1, -2, 3, -4, 5, -6;
  Vec6 f;
  Mat6 P;
  const ProjectionResult pr =
      project_motion_force(J, Vec6::Ones(), g, kSingularRcond, kDamping, &f, &P);
  EXPECT_FALSE(pr.singular);
  EXPECT_EQ(f, g);
  EXPECT_TRUE(P.isIdentity(0.0));
}

// ----------------------------------------------------------- active columns

TEST(ActiveColumns, PicksUnlockedColumnsInOrder) {
  std::mt19937 rng(108);
  const VmJacobian J = random_jacobian(&rng, 5);
  for (JointMask mask = 0; mask < 32; ++mask) {
    VmJacobian out;
    active_columns(J, mask, &out);
    std::vector<int> expected;
    for (int j = 0; j < 5; ++j)
      if (!((mask >> j) & 1u)) expected.push_back(j);
    ASSERT_EQ(out.cols(), static_cast<int>(expected.size())) << mask;
    ASSERT_EQ(out.rows(), 6);
    for (size_t k = 0; k < expected.size(); ++k) {
      EXPECT_TRUE(out.col(static_cast<int>(k)) == J.col(expected[k]))
          << "mask " << mask << " column " << k;
    }
  }
  // bits beyond the VM's joints change nothing
  VmJacobian out;
  active_columns(J, JointMask{1} << 7, &out);
  EXPECT_TRUE(out == J);
}

// ---------------------------------------------------------------- placement

VmMount turned_mount() {
  VmMount m;
  m.origin = Vec3(10.0, -20.0, 5.0);
  m.R = Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, -0.5).normalized())
            .toRotationMatrix();
  return m;
}

struct Case {
  std::unique_ptr<VirtualMechanism> vm;
  std::string name;
};

// kinds x {default, turned mount} x {50, 0.05}
std::vector<Case> cases(std::vector<VmKind> kinds) {
  std::vector<Case> out;
  for (VmKind kind : kinds) {
    for (int turned = 0; turned < 2; ++turned) {
      for (double L : {50.0, 0.05}) {
        const VmMount m = turned ? turned_mount() : VmMount{};
        std::unique_ptr<VirtualMechanism> vm;
        if (kind == VmKind::kCircle) vm = std::make_unique<CircleVm>(m, L);
        if (kind == VmKind::kSphere) vm = std::make_unique<SphereVm>(m, L);
        if (kind == VmKind::kSurface) vm = std::make_unique<SurfaceVm>(m, L);
        out.push_back({std::move(vm), std::string(vm_kind_name(kind)) +
                                          (turned ? " turned" : " default") +
                                          " L=" + std::to_string(L)});
      }
    }
  }
  return out;
}


// the cost r^T W r, from the residual
double cost_at(const VirtualMechanism& vm, const RmPose& rm, const Vec6& w,
               const VmAngles& theta) {
  const Vec6 r = placement_residual(vm, rm, theta);
  return r.dot(w.cwiseProduct(r));
}

// |J^T W r| relative to |J| |W r|: zero at a stationary point of r^T W r
// (with equal orientation weights J_rot^T r_o is exactly half the gradient
// of |r_o|^2, so this is first-order optimality of the cost)
double optimality(const VirtualMechanism& vm, const RmPose& rm, const Vec6& w,
                  const VmAngles& theta) {
  VmJacobian J;
  vm.jacobian(theta, &J);
  const Vec6 Wr = w.cwiseProduct(placement_residual(vm, rm, theta));
  return (X(J).transpose() * Wr).norm() / (J.norm() * Wr.norm() + 1e-300);
}

Vec6 position_weights() { return (Vec6() << 1, 1, 1, 0, 0, 0).finished(); }
Vec6 orientation_weights() { return (Vec6() << 0, 0, 0, 1, 1, 1).finished(); }

// identity: the placement residual is p - X_V and, in the orientation rows,
// the rotation vector carrying the link axis onto the stylus axis
TEST(PlacementResidual, PositionAndRotationCarryingLinkOntoStylus) {
  std::mt19937 rng(200);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere,
                              VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    for (int k = 0; k < 100; ++k) {
      const VmAngles theta = random_theta(vm, &rng);
      RmPose rm{vm.mount().origin + vm.length() * random_unit(&rng),
                random_unit(&rng)};
      const Vec6 r = placement_residual(vm, rm, theta);
      const VmPose pose = vm.pose(theta);
      EXPECT_LE((r.head<3>() - (rm.p - pose.p)).norm(), 1e-12 * vm.length());
      if (vm.kind() != VmKind::kCircle) {
        const Vec3 o = r.tail<3>();
        EXPECT_LE((Eigen::AngleAxisd(o.norm(), o.normalized()) * pose.axis -
                   rm.axis)
                      .norm(),
                  1e-12)
            << c.name;
      }
    }
  }
}

// An RM position where Gauss-Newton under W_p contracts at a rate
// |1 - d/L| <= 1/2: d, the distance from the pivot (sphere) or the in-plane
// distance (circle, which also gets an out-of-plane offset), in [0.5, 1.5] L
Vec3 rm_position(const VirtualMechanism& vm, std::mt19937* rng) {
  const double L = vm.length();
  const double d = uniform(rng, 0.5, 1.5) * L;
  if (vm.kind() == VmKind::kCircle) {
    const double a = uniform(rng, -kPi, kPi);
    const Mat3& R = vm.mount().R;
    return vm.mount().origin + d * (std::cos(a) * R.col(0) + std::sin(a) * R.col(1)) +
           uniform(rng, -L, L) * R.col(2);
  }
  return vm.mount().origin + d * random_unit(rng);
}

// one plain Gauss-Newton step at theta, computed here: the minimum-norm
// least-squares solution of W^(1/2) J delta = W^(1/2) r (Jacobi SVD)
VectorXd plain_gauss_newton_step(const VirtualMechanism& vm, const RmPose& rm,
                                 const Vec6& w, const VmAngles& theta) {
  VmJacobian J;
  vm.jacobian(theta, &J);
  const MatrixXd B = w.cwiseSqrt().asDiagonal() * X(J);
  const VectorXd b =
      w.cwiseSqrt().asDiagonal() * VectorXd(placement_residual(vm, rm, theta));
  Eigen::JacobiSVD<MatrixXd> svd(B, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-12);
  return svd.solve(b);
}

// identity: with W_p the Gauss-Newton placement reaches the closed-form
// nearest() point (circle, sphere) from random starts. Where the iteration
// contracts at a rate <= 1/2 (as here), a last step below the documented
// tolerance leaves at most that much: allow 2 tolerances (x L), or 1e-9 L
// if that is larger.
TEST(PlaceGaussNewton, PositionWeightGivesNearest) {
  std::mt19937 rng(201);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    PlacementOptions opt;
    opt.weights = position_weights();
    int not_converged = 0;
    double worst = 0;
    for (int k = 0; k < 500; ++k) {
      const RmPose rm{rm_position(vm, &rng), random_unit(&rng)};
      VmAngles theta = random_theta(vm, &rng);
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      if (!res.converged) ++not_converged;
      VmAngles closed = vm.zero_angles();
      ASSERT_TRUE(vm.nearest(rm, &closed));
      worst = std::max(worst, (vm.pose(theta).p - vm.pose(closed).p).norm());
      EXPECT_NEAR(res.cost, cost_at(vm, rm, opt.weights, theta),
                  1e-12 * L * L);
    }
    EXPECT_EQ(not_converged, 0) << c.name;
    EXPECT_LE(worst, std::max(1e-9, 2 * opt.tolerance) * L)
        << c.name << ": worst |X_GN - X_nearest| / L = " << worst / L;
  }
}

// identity: where place_gauss_newton reports convergence, one more plain
// Gauss-Newton step (computed here) is below the documented tolerance
// ("stop when max |delta theta| falls below this"), within a factor 10
TEST(PlaceGaussNewton, ReturnedPointMeetsTheStepTolerance) {
  std::mt19937 rng(208);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    for (int blend = 0; blend < 2; ++blend) {
      PlacementOptions opt;
      opt.weights = position_weights();
      if (blend) opt.weights.tail<3>().setConstant(L * L);
      opt.max_iterations = 1000;
      double worst = 0;
      for (int k = 0; k < 500; ++k) {
        const RmPose rm{rm_position(vm, &rng), random_unit(&rng)};
        VmAngles theta = random_theta(vm, &rng);
        if (!place_gauss_newton(vm, rm, opt, JointMask{0}, &theta).converged)
          continue;  // counted by the other tests
        worst = std::max(worst, plain_gauss_newton_step(vm, rm, opt.weights,
                                                        theta)
                                    .cwiseAbs()
                                    .maxCoeff());
      }
      EXPECT_LE(worst, 10 * opt.tolerance)
          << c.name << " blend " << blend << ": worst next step " << worst;
    }
  }
}

// identity: started at the closed form, W_p placement confirms it at once
TEST(PlaceGaussNewton, SeededAtTheClosedFormStopsAtOnce) {
  std::mt19937 rng(202);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    PlacementOptions opt;
    opt.weights = position_weights();
    for (int k = 0; k < 100; ++k) {
      const RmPose rm{vm.mount().origin +
                          uniform(&rng, 0.1, 3.0) * L * random_unit(&rng),
                      random_unit(&rng)};
      VmAngles theta = random_theta(vm, &rng);
      ASSERT_TRUE(vm.nearest(rm, &theta));
      const Vec3 p0 = vm.pose(theta).p;
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      EXPECT_TRUE(res.converged) << c.name;
      EXPECT_LE(res.iterations, 2) << c.name;
      EXPECT_LE((vm.pose(theta).p - p0).norm(), 1e-9 * L) << c.name;
    }
  }
}

// identity: with W_o the placement turns the link onto aligned()'s axis
// (sphere: the stylus axis; circle: its normalised in-plane projection)
TEST(PlaceGaussNewton, OrientationWeightGivesAligned) {
  std::mt19937 rng(203);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    PlacementOptions opt;
    opt.weights = orientation_weights();
    for (int k = 0; k < 200; ++k) {
      const RmPose rm{vm.mount().origin + Vec3(1, 2, 3), random_unit(&rng)};
      VmAngles theta = random_theta(vm, &rng);
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      EXPECT_TRUE(res.converged) << c.name;
      VmAngles closed = vm.zero_angles();
      ASSERT_TRUE(vm.aligned(rm, &closed));
      EXPECT_LE((vm.pose(theta).axis - vm.pose(closed).axis).norm(), 1e-9)
          << c.name << " iterations " << res.iterations;
      EXPECT_LE(res.cost, 1e-16) << c.name;  // the link reaches the axis
    }
  }
}

// identity: a blend W = (1,1,1,w,w,w) (w = L^2: a radian weighs like an arc
// of length L) places the VM no worse than either closed form, at a
// stationary point of the cost (J^T W r = 0); on the circle, between the
// nearest and the aligned angles
TEST(PlaceGaussNewton, BlendIsOptimalAndBetweenTheClosedForms) {
  std::mt19937 rng(204);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    PlacementOptions opt;
    opt.weights << 1, 1, 1, L * L, L * L, L * L;
    // random stylus axes make large residuals, where Gauss-Newton contracts
    // only linearly (rates up to ~0.9): this checks the optimum, not speed
    opt.max_iterations = 1000;
    int between_checked = 0, not_converged = 0;
    double worst_optimality = 0;
    for (int k = 0; k < 200; ++k) {
      const RmPose rm{rm_position(vm, &rng), random_unit(&rng)};
      VmAngles near = vm.zero_angles(), aligned = vm.zero_angles();
      ASSERT_TRUE(vm.nearest(rm, &near));
      ASSERT_TRUE(vm.aligned(rm, &aligned));
      VmAngles theta = near;  // the controller's seed
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      if (!res.converged) ++not_converged;
      const double cost = cost_at(vm, rm, opt.weights, theta);
      const double tol = 1e-12 * L * L;
      EXPECT_LE(cost, cost_at(vm, rm, opt.weights, near) + tol) << c.name;
      EXPECT_LE(cost, cost_at(vm, rm, opt.weights, aligned) + tol) << c.name;
      worst_optimality =
          std::max(worst_optimality, optimality(vm, rm, opt.weights, theta));
      if (vm.kind() == VmKind::kCircle) {
        const double span = wrap_angle(aligned[0] - near[0]);
        if (std::abs(span) < kPi - 0.1) {
          const double t = wrap_angle(theta[0] - near[0]);
          EXPECT_GE(t * span, -1e-9) << c.name;  // same side as aligned
          EXPECT_LE(std::abs(t), std::abs(span) + 1e-9) << c.name;
          ++between_checked;
        }
      }
    }
    EXPECT_EQ(not_converged, 0) << c.name;
    EXPECT_LE(worst_optimality, 1e-8) << c.name;
    if (vm.kind() == VmKind::kCircle) {
      EXPECT_GT(between_checked, 150);
    }
  }
}

// An RM that sits near the VM (as under control: 1e-4 L off the path, the
// stylus along the link), the VM placed there, then the RM moved by `move`
// times L and its stylus tilted by `move` rad. Returns the iterations of
// the warm-started placement, or -1 if it did not converge.
int warm_start_iterations(const VirtualMechanism& vm, const Vec6& weights,
                          double move, std::mt19937* rng) {
  const double L = vm.length();
  VmAngles theta = random_theta(vm, rng);
  const VmPose at = vm.pose(theta);
  RmPose rm{at.p + 1e-4 * L * at.axis, at.axis};
  PlacementOptions cold;
  cold.weights = weights;
  cold.max_iterations = 200;
  if (!place_gauss_newton(vm, rm, cold, JointMask{0}, &theta).converged)
    return -2;
  rm.p += move * L * random_unit(rng);
  rm.axis = Eigen::AngleAxisd(move, random_unit(rng)) * rm.axis;
  PlacementOptions opt;  // the controller's 20 iterations
  opt.weights = weights;
  const PlacementResult res =
      place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
  return res.converged ? res.iterations : -1;
}

// identity: from the previous answer, after a small move (1e-4 L, 1e-4 rad)
// of an RM near the path, placement converges in <= 3 iterations (two
// contracting steps and the confirming one)
TEST(PlaceGaussNewton, WarmStartConvergesInFewIterations) {
  std::mt19937 rng(205);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const double L = c.vm->length();
    for (int blend = 0; blend < 2; ++blend) {
      Vec6 w = position_weights();
      if (blend) w.tail<3>().setConstant(L * L);
      int worst = 0;
      for (int k = 0; k < 200; ++k) {
        const int it = warm_start_iterations(*c.vm, w, 1e-4, &rng);
        ASSERT_GT(it, 0) << c.name << " blend " << blend;
        worst = std::max(worst, it);
      }
      EXPECT_LE(worst, 3) << c.name << " blend " << blend;
    }
  }
}

// identity: a larger move (1e-3 L: 50 mm/s at 1 kHz for L = 50 mm) needs
// one more contracting step (the rate |1 - d/L| is ~1e-3): 3 steps and the
// confirming iteration; allow 5. The iteration must not idle once the step
// is down at the cost's rounding level.
TEST(PlaceGaussNewton, WarmStartAfterALargerMoveDoesNotIdle) {
  std::mt19937 rng(209);
  for (const Case& c : cases({VmKind::kCircle, VmKind::kSphere})) {
    const double L = c.vm->length();
    for (int blend = 0; blend < 2; ++blend) {
      Vec6 w = position_weights();
      if (blend) w.tail<3>().setConstant(L * L);
      int worst = 0, over = 0;
      for (int k = 0; k < 500; ++k) {
        const int it = warm_start_iterations(*c.vm, w, 1e-3, &rng);
        ASSERT_GT(it, 0) << c.name << " blend " << blend;
        worst = std::max(worst, it);
        if (it > 5) ++over;
      }
      EXPECT_LE(worst, 5) << c.name << " blend " << blend << ": " << over
                          << " of 500 took more than 5 iterations";
    }
  }
}

// identity: locked joints stay exactly where they were; the surface with its
// contact locked (mask 3) under W_p turns the probe toward the RM, which is
// its nearest() closed form
TEST(PlaceGaussNewton, LockedJointsStayAndSurfaceStickingIsNearest) {
  std::mt19937 rng(206);
  for (const Case& c : cases({VmKind::kSurface})) {
    const VirtualMechanism& vm = *c.vm;
    const double L = vm.length();
    for (const Vec6& w : {position_weights(), Vec6(Vec6::Ones())}) {
      PlacementOptions opt;
      opt.weights = w;
      double worst = 0;
      for (int k = 0; k < 100; ++k) {
        const VmAngles start = random_theta(vm, &rng);
        const RmPose rm{static_cast<const SurfaceVm&>(vm).contact(start) +
                            uniform(&rng, 0.5, 1.5) * L * random_unit(&rng),
                        random_unit(&rng)};
        VmAngles theta = start;
        const PlacementResult res =
            place_gauss_newton(vm, rm, opt, JointMask{3}, &theta);
        EXPECT_TRUE(res.converged) << c.name;
        EXPECT_EQ(theta[0], start[0]) << c.name;
        EXPECT_EQ(theta[1], start[1]) << c.name;
        if (w[3] == 0.0) {
          VmAngles closed = start;
          ASSERT_TRUE(vm.nearest(rm, &closed));
          worst = std::max(worst, (vm.pose(theta).p - vm.pose(closed).p).norm());
        }
      }
      EXPECT_LE(worst, std::max(1e-9, 2 * opt.tolerance) * L)
          << c.name << ": worst |X_GN - X_nearest| / L = " << worst / L;
    }
  }
}

// |J^T W r| over |J^T W J|: how far (in joint units) a Gauss-Newton step
// would still go from theta; zero at a stationary point
double gradient_over_curvature(const VirtualMechanism& vm, const RmPose& rm,
                               const Vec6& w, const VmAngles& theta) {
  const MatrixXd J = X([&] {
    VmJacobian Jv;
    vm.jacobian(theta, &Jv);
    return Jv;
  }());
  const VectorXd Wr = w.cwiseProduct(placement_residual(vm, rm, theta));
  const MatrixXd A = J.transpose() * w.asDiagonal() * J;
  return (J.transpose() * Wr).norm() / A.norm();
}

// identity: the surface with W = I (all five joints free): J^T W r = 0 at the
// result, the contact lies on the plane and under the handle along the link,
// and the cost is no larger than at the aligned closed form (stylus axis,
// contact under the tip). The surface's iteration contracts only linearly
// (rates ~0.9 with large residuals, as control_law.h says), so a last step
// below the tolerance can leave ~10 tolerances: J^T W r is checked against
// |J^T W J| times 10 tolerances, and relative to |J| |W r| at 1e-7.
TEST(PlaceGaussNewton, SurfaceIdentityWeightIsOptimalOnThePlane) {
  std::mt19937 rng(207);
  for (const Case& c : cases({VmKind::kSurface})) {
    const auto& vm = static_cast<const SurfaceVm&>(*c.vm);
    const double L = vm.length();
    const Vec3 o = vm.mount().origin, n = vm.normal();
    PlacementOptions opt;
    opt.weights = Vec6::Ones();
    opt.max_iterations = 1000;  // the optimum, not the speed
    int not_converged = 0;
    double worst_optimality = 0, worst_gradient = 0;
    for (int k = 0; k < 100; ++k) {
      // a stylus standing above the plane, more or less upright
      const Vec3 axis = (n + 0.7 * random_unit(&rng)).normalized();
      const Vec3 p = o + uniform(&rng, -L, L) * vm.mount().R.col(0) +
                     uniform(&rng, -L, L) * vm.mount().R.col(1) +
                     uniform(&rng, 0.3, 2.0) * L * n;
      const RmPose rm{p, axis};
      VmAngles aligned = random_theta(vm, &rng);
      ASSERT_TRUE(vm.aligned(rm, &aligned));
      VmAngles theta = aligned;
      const PlacementResult res =
          place_gauss_newton(vm, rm, opt, JointMask{0}, &theta);
      if (!res.converged) ++not_converged;
      worst_optimality =
          std::max(worst_optimality, optimality(vm, rm, opt.weights, theta));
      worst_gradient = std::max(
          worst_gradient, gradient_over_curvature(vm, rm, opt.weights, theta));
      const Vec3 contact = vm.contact(theta);
      EXPECT_NEAR((contact - o).dot(n), 0.0, 1e-12 * (1 + L)) << c.name;
      const VmPose pose = vm.pose(theta);
      EXPECT_LE((pose.p - L * pose.axis - contact).norm(), 1e-12 * (1 + L));
      EXPECT_LE(cost_at(vm, rm, opt.weights, theta),
                cost_at(vm, rm, opt.weights, aligned) + 1e-12 * (1 + L * L))
          << c.name;
    }
    EXPECT_EQ(not_converged, 0) << c.name;
    EXPECT_LE(worst_gradient, 10 * opt.tolerance) << c.name;
    EXPECT_LE(worst_optimality, 1e-7) << c.name;
  }
}

}  // namespace
}  // namespace vmh
