// A least-squares fit of the Omni's uncertain geometry to recorded pairs of
// (reported joint angles, the device's own wrist transform), for compare's
// kinematics (compare_kinematics.h): whether the device's transform differs
// from the project's FK by a wrong link length, a joint offset, a base
// offset or a potentiometer gain, and by how much.
//
// Model of one sample (device frame, mm; angles in the device convention,
// t3 absolute, controller/device_frame.h):
//   t_i      = t_reported_i + offset_i                (i = 1..3)
//   t_i      = scale_i * t_reported_i + offset_i      (i = 4..6, the pots)
//   p_mm     = base_to_device_mm(nominal, FK_{l1,l2}(t).p) + base_offset_mm
//   R_device = base_to_device_rotation(FK(t).R) * C
// C is the device's fixed rotation convention (identity for the emulator;
// an OpenHaptics device may number or sign its stylus axes otherwise). It
// is estimated between Levenberg-Marquardt rounds as the best rotation over
// the recording and snapped to the nearest signed permutation when within
// 10 deg of one. A rotation about the stylus axis z6 after joint 6 is the
// same as an offset on t6, so t6's offset is fitted only when C is snapped;
// otherwise it is held at 0.
//
// Residuals per sample: the wrist position (3, mm) and the three columns of
// the rotation (9, weighted 100 mm per rad: an angle error of 0.01 rad
// counts as a 1 mm miss, the size a hand notices at the stylus tip).
// Uncertainties: 1 sigma from sigma^2 (J^T J)^-1, sigma^2 the residual
// variance per degree of freedom (exact for independent noise; quantized
// angles of a slow motion are correlated in time, so read them as a lower
// bound). Derivatives by central differences (geometry_residual_jacobian;
// tests/bringup/geometry_fit_test.cc holds them against the
// published OpenHaptics formula's analytic ones).
#ifndef VMHAPTICS_BRINGUP_GEOMETRY_FIT_H_
#define VMHAPTICS_BRINGUP_GEOMETRY_FIT_H_

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

#include "controller/types.h"

namespace vmh::bringup {

// The parameter vector, in this order:
//   0 l1_mm, 1 l2_mm, 2..4 base_offset_{x,y,z}_mm (device frame),
//   5..10 t1..t6 offset_rad, 11..13 t4..t6 scale (dimensionless)
inline constexpr int kGeometryParams = 14;
using GeometryVec = Eigen::Matrix<double, kGeometryParams, 1>;
enum GeometryParam {
  kL1 = 0, kL2 = 1, kBaseX = 2, kOffsetT1 = 5, kScaleT4 = 11
};

// the nominal vector: OmniParams' lengths, no offsets, unit scales
GeometryVec nominal_geometry();
// "l1", "l2", "base_offset_x", ..., "t1_offset", ..., "t4_scale", ...
std::string geometry_param_name(int i);
std::string geometry_param_unit(int i);  // "mm", "rad" or "1"

// One recorded sample: the reported device angles (already read through
// the ReadingMap) and the device's transform, device frame.
struct PoseSample {
  Joints t_reported_device_rad = Joints::Zero();
  Vec3 p_device_mm = Vec3::Zero();
  Mat3 R_device = Mat3::Identity();  // the device's own convention
};

// The model's wrist position (mm) and stylus rotation (before C), device
// frame, for parameters x
void geometry_model(const GeometryVec& x, const Joints& t_reported_device_rad,
                    Vec3* p_device_mm, Mat3* R_device);

// The 12 residuals of one sample (3 position mm, 9 rotation entries times
// rotation_weight_mm_per_rad) and their derivatives (central differences)
using GeometryResidual = Eigen::Matrix<double, 12, 1>;
using GeometryJacobian = Eigen::Matrix<double, 12, kGeometryParams>;
GeometryResidual geometry_residual(const GeometryVec& x, const PoseSample& s,
                                   const Mat3& C, double rotation_weight_mm_per_rad);
GeometryJacobian geometry_residual_jacobian(const GeometryVec& x,
                                            const PoseSample& s, const Mat3& C,
                                            double rotation_weight_mm_per_rad);

struct ErrorStats {
  double mean = 0, rms = 0, p95 = 0, max = 0;
  std::size_t count = 0;
};
// Throws std::invalid_argument when `values` is empty
ErrorStats error_stats(std::vector<double> values);

struct FittedParam {
  std::string name;
  std::string unit;
  double nominal = 0, fitted = 0, sigma = 0;
  bool free = true;  // false: held at nominal (unobservable here)
};

struct GeometryFitOptions {
  // evenly spaced over the recording; more adds time, not information
  std::size_t max_samples = 1500;
  double rotation_weight_mm_per_rad = 100.0;
  // what "explains the error" means: p95 after the fit below these (the
  // kinematics checks' thresholds, compare_kinematics.h)
  double position_threshold_mm = 1.0;
  double rotation_threshold_deg = 2.0;
  int max_iterations = 60;
};

struct GeometryFit {
  GeometryVec x = GeometryVec::Zero();
  std::vector<FittedParam> params;  // kGeometryParams entries, in order
  Mat3 convention = Mat3::Identity();  // C
  bool convention_snapped = true;      // C is a signed permutation
  // errors per sample: position |dp| (mm), rotation angle of
  // (R_model C)^T R_device (deg); "before" at the nominal geometry with C
  // fitted there, "after" at the fitted one
  ErrorStats position_before_mm, position_after_mm;
  ErrorStats rotation_before_deg, rotation_after_deg;
  std::size_t samples_used = 0;
  int iterations = 0;
  // the fitted values are within what a device could have (lengths within
  // 10 %, offsets within 0.3 rad, scales within 20 %): a sign error fitted
  // as a scale of -1 is not an explanation
  bool plausible = false;
  // p95 after the fit below both thresholds, and plausible
  bool explains = false;
};

// Throws std::invalid_argument when fewer than 20 samples are given or a
// sample is not finite (naming its index).
GeometryFit fit_geometry(const std::vector<PoseSample>& samples,
                         const GeometryFitOptions& options = {});

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_GEOMETRY_FIT_H_
