// bringup/geometry_fit: the model against the published OpenHaptics
// formula (tests/support/openhaptics_reference.h), its derivatives against
// that formula's analytic ones, and the fit recovering a perturbed geometry
// with honest uncertainties.
#include "bringup/geometry_fit.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_params.h"
#include "tests/support/openhaptics_reference.h"

namespace vmh::bringup {
namespace {

constexpr double kL = 133.35;  // nominal l1 = l2, mm (docs/sources.md §4)

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}
Mat3 rot(double a, const Vec3& axis) { return Eigen::AngleAxisd(a, axis).matrix(); }

// device angles uniformly inside the device ranges
Joints random_device_joints(std::mt19937* rng) {
  Joints lo, hi;
  device_joint_ranges(OmniParams{}, &lo, &hi);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Joints t;
  for (int i = 0; i < 6; ++i) t[i] = lo[i] + 0.9 * u(*rng) * (hi[i] - lo[i]);
  return t;
}

// The published formula with the device frame's origin held at the nominal
// device's (the OpenHaptics formula moves it with l1 and l2)
Vec3 reference_wrist_mm(const Joints& t, double l1, double l2) {
  return testing::openhaptics_wrist_mm(t, l1, l2) + Vec3(0, kL - l2, l1 - kL);
}

TEST(GeometryFit, ModelAtNominalIsThePublishedFormula) {
  std::mt19937 rng(3);
  for (int k = 0; k < 20; ++k) {
    const Joints t = random_device_joints(&rng);
    Vec3 p;
    Mat3 R;
    geometry_model(nominal_geometry(), t, &p, &R);
    EXPECT_LT((p - testing::openhaptics_wrist_mm(t, kL, kL)).norm(), 1e-9);
    EXPECT_LT((R - testing::openhaptics_stylus_rotation(t)).norm(), 1e-9);
  }
}

// d residual / d parameter by the fit's central differences against the
// derivatives of the published formula worked out by hand
TEST(GeometryFit, DerivativesMatchTheAnalyticOnes) {
  std::mt19937 rng(5);
  const double w = 100.0;
  for (int k = 0; k < 10; ++k) {
    const Joints t = random_device_joints(&rng);
    GeometryVec x = nominal_geometry();
    x[kL1] = 136.0;
    x[kL2] = 131.0;
    PoseSample s;
    s.t_reported_device_rad = t;
    const GeometryJacobian J = geometry_residual_jacobian(x, s, Mat3::Identity(), w);
    const double l1 = x[kL1], l2 = x[kL2];
    const double s1 = std::sin(t[0]), c1 = std::cos(t[0]);
    const double reach = l1 * std::cos(t[1]) + l2 * std::sin(t[2]);
    Eigen::Matrix<double, 3, kGeometryParams> dp = Eigen::Matrix<double, 3, kGeometryParams>::Zero();
    dp.col(kL1) << -s1 * std::cos(t[1]), std::sin(t[1]), c1 * std::cos(t[1]);
    dp.col(kL2) << -s1 * std::sin(t[2]), -std::cos(t[2]), c1 * std::sin(t[2]);
    dp.block<3, 3>(0, kBaseX).setIdentity();
    dp.col(kOffsetT1) << -c1 * reach, 0, -s1 * reach;
    dp.col(kOffsetT1 + 1) << s1 * l1 * std::sin(t[1]), l1 * std::cos(t[1]),
        -c1 * l1 * std::sin(t[1]);
    dp.col(kOffsetT1 + 2) << -s1 * l2 * std::cos(t[2]), l2 * std::sin(t[2]),
        c1 * l2 * std::cos(t[2]);
    EXPECT_LT((J.topRows<3>() - dp).cwiseAbs().maxCoeff(), 1e-5) << "sample " << k;

    // R = Ry(-t1) Rx(-t3) Ry(t4) Rx(-t5) Rz(-t6): each gimbal angle's
    // derivative inserts its axis' generator at its place in the product
    const Mat3 A = rot(-t[0], Vec3::UnitY()) * rot(-t[2], Vec3::UnitX());
    const Mat3 R4 = rot(t[3], Vec3::UnitY()), R5 = rot(-t[4], Vec3::UnitX()),
               R6 = rot(-t[5], Vec3::UnitZ());
    const Mat3 dR4 = A * R4 * skew(Vec3::UnitY()) * R5 * R6;
    const Mat3 dR5 = A * R4 * R5 * -skew(Vec3::UnitX()) * R6;
    const Mat3 dR6 = A * R4 * R5 * R6 * -skew(Vec3::UnitZ());
    const Mat3 dR[3] = {dR4, dR5, dR6};
    for (int g = 0; g < 3; ++g) {
      const Eigen::Matrix<double, 9, 1> expect =
          w * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dR[g].data());
      EXPECT_LT((J.col(kOffsetT1 + 3 + g).tail<9>() - expect).cwiseAbs().maxCoeff(), 1e-4);
      EXPECT_LT((J.col(kScaleT4 + g).tail<9>() - t[3 + g] * expect).cwiseAbs().maxCoeff(),
                1e-4);
      EXPECT_LT(J.col(kScaleT4 + g).head<3>().norm(), 1e-9) << "the pots move no wrist";
    }
  }
}

TEST(GeometryFit, ErrorStatsByHand) {
  std::vector<double> v;
  for (int i = 1; i <= 20; ++i) v.push_back(i);
  const ErrorStats e = error_stats(v);
  EXPECT_DOUBLE_EQ(e.mean, 10.5);
  EXPECT_DOUBLE_EQ(e.max, 20.0);
  EXPECT_DOUBLE_EQ(e.p95, 19.0);  // the 19th of 20 sorted values
  EXPECT_NEAR(e.rms, std::sqrt(2870.0 / 20.0), 1e-12);  // sum of squares 1..20
  EXPECT_THROW(error_stats({}), std::invalid_argument);
}

// A perturbed geometry, the measurements from the published formula with
// Gaussian noise of the same size on all 12 residuals (0.05 mm; 0.0005 on
// the rotation's entries, 0.05 mm at 100 mm/rad): the true values lie within
// 4 sigma of the fitted ones for every seed.
TEST(GeometryFit, RecoversAPerturbedGeometryWithinItsUncertainty) {
  GeometryVec truth = nominal_geometry();
  truth[kL1] = 136.0;
  truth[kL2] = 131.5;
  truth.segment<3>(kBaseX) << 0.6, -0.4, 0.3;
  truth.segment<6>(kOffsetT1) << 0.004, -0.012, 0.006, 0.02, -0.015, 0.01;
  truth.tail<3>() << 1.03, 0.98, 1.01;
  const double noise_mm = 0.05;
  int checked = 0;
  for (std::uint32_t seed : {11u, 12u, 13u, 14u}) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise_mm);
    std::vector<PoseSample> samples;
    for (int k = 0; k < 1000; ++k) {
      PoseSample s;
      s.t_reported_device_rad = random_device_joints(&rng);
      Joints t = s.t_reported_device_rad;
      for (int i = 3; i < 6; ++i) t[i] *= truth[kScaleT4 + i - 3];
      t += truth.segment<6>(kOffsetT1);
      s.p_device_mm = reference_wrist_mm(t, truth[kL1], truth[kL2]) +
                      truth.segment<3>(kBaseX) + Vec3(n(rng), n(rng), n(rng));
      s.R_device = testing::openhaptics_stylus_rotation(t);
      for (int e = 0; e < 9; ++e) s.R_device.data()[e] += n(rng) / 100.0;
      samples.push_back(s);
    }
    const GeometryFit f = fit_geometry(samples);
    EXPECT_TRUE(f.explains) << f.plausible << ' ' << f.rotation_after_deg.p95;
    EXPECT_TRUE(f.convention_snapped);
    EXPECT_GT(f.position_before_mm.p95, 3.0) << "the perturbation shows before the fit";
    EXPECT_LT(f.position_after_mm.p95, 0.2);
    ASSERT_EQ(f.params.size(), static_cast<std::size_t>(kGeometryParams));
    for (int k = 0; k < kGeometryParams; ++k) {
      const FittedParam& p = f.params[k];
      ASSERT_TRUE(p.free) << p.name;
      EXPECT_GT(p.sigma, 0.0) << p.name;
      EXPECT_LT(std::abs(p.fitted - truth[k]), 4.0 * p.sigma)
          << p.name << " seed " << seed << ": fitted " << p.fitted << " true " << truth[k]
          << " sigma " << p.sigma;
      ++checked;
    }
    EXPECT_LT(f.params[kL1].sigma, 0.05) << "1000 samples pin l1 to hundredths of a mm";
  }
  EXPECT_EQ(checked, 4 * kGeometryParams);
}

TEST(GeometryFit, BadInputIsNamed) {
  std::vector<PoseSample> few(5);
  try {
    fit_geometry(few);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at least 20"), std::string::npos) << e.what();
  }
  std::vector<PoseSample> bad(30);
  bad[7].p_device_mm.x() = std::nan("");
  try {
    fit_geometry(bad);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 7"), std::string::npos) << e.what();
  }
  EXPECT_THROW(geometry_param_name(kGeometryParams), std::invalid_argument);
}

}  // namespace
}  // namespace vmh::bringup
