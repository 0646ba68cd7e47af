// Checks of controller/control_law against routes that do not share its
// code: the projector's algebraic identities, the projection computed here
// on dynamic matrices with Eigen's full-pivot LU and an explicit inverse,
// and range(J) from a Jacobi SVD of J. The placement's checks are in
// control_law_placement_test.cc.
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
#include "controller/vm_circle.h"
#include "controller/vm_line.h"
#include "controller/vm_registry.h"
#include "controller/vm_sphere.h"
#include "controller/vm_surface.h"
#include "tests/support/random_vm.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;
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

// project_motion_force_sphere against the general path on the sphere's own
// J: the same f to rounding (relative 1e-12 of |g|, observed ~1e-14), the
// same rcond (1e-8 relative, the general path's closed-form eigenvalues
// carry trigonometric rounding), the same flag; near the pole and for a W_A
// that is not block-uniform it is the general path itself.
TEST(ProjectMotionForceSphere, EqualsTheGeneralProjection) {
  std::mt19937 rng(18);
  int structured = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    VmMount mount;
    mount.origin = random_vec6(&rng, 100.0).head<3>();
    mount.R = Eigen::AngleAxisd(uniform(&rng, 0.0, kPi), random_unit(&rng))
                  .toRotationMatrix();
    const double L = trial % 2 == 0 ? 50.0 : uniform(&rng, 0.1, 200.0);
    const SphereVm vm(mount, L);
    VmAngles theta = random_theta(vm, &rng);
    // a quarter of them within 1e-3 .. 1e-9 rad of a pole
    if (trial % 4 == 3) {
      theta[1] = std::pow(10.0, uniform(&rng, -9.0, -3.0)) +
                 (trial % 8 == 7 ? kPi : 0.0);
    }
    VmJacobian J;
    vm.jacobian(theta, &J);
    Vec6 W = Vec6::Ones();
    if (trial % 3 == 1) {
      const double a = std::pow(10.0, uniform(&rng, -1.0, 1.0));
      const double b = std::pow(10.0, uniform(&rng, -1.0, 1.0));
      W << a, a, a, b, b, b;
    } else if (trial % 3 == 2) {
      W = random_weights(&rng);
    }
    const Vec6 g = random_vec6(&rng, 10.0);
    Vec6 f_general, f_sphere;
    const ProjectionResult pg = project_motion_force(
        J, W, g, kSingularRcond, kDamping, &f_general);
    const ProjectionResult ps = project_motion_force_sphere(
        J, L, std::sin(theta[1]), std::cos(theta[1]), W, g, kSingularRcond,
        kDamping, &f_sphere);
    const bool near_pole = std::abs(std::sin(theta[1])) < 1e-3;
    if (!near_pole && trial % 3 != 2) ++structured;
    EXPECT_LE((f_sphere - f_general).norm(), 1e-12 * g.norm() / pg.rcond)
        << "trial " << trial;
    if (!near_pole) {
      EXPECT_LE((f_sphere - f_general).norm(), 1e-12 * g.norm())
          << "trial " << trial;
    }
    EXPECT_NEAR(ps.rcond, pg.rcond, 1e-8 * pg.rcond + 1e-15)
        << "trial " << trial;
    EXPECT_EQ(ps.singular, pg.singular) << "trial " << trial;
  }
  EXPECT_GT(structured, 1000);
}

// ---------------------------------------------------------------- placement
}  // namespace
}  // namespace vmh
