// Fixed-size Eigen types shared by the controller library.
//
// Everything in controller/ works in SI units (m, rad, N, N·m, s) unless a name
// carries another unit suffix (_mm, _mNm). Frames are named in identifiers:
// `_base` is the DH base frame of Table B.1 (z up through joint 1), `_device`
// is the OpenHaptics device frame (x right, y up, z toward the user).
#ifndef VMHAPTICS_CONTROLLER_TYPES_H_
#define VMHAPTICS_CONTROLLER_TYPES_H_

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace vmh {

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// joint angles of the six Omni joints, q1..q6; the convention (DH or device)
// is stated wherever one is passed
using Joints = Vec6;

// millimetres per metre: the device frame and OpenHaptics work in mm
inline constexpr double kMmPerM = 1000.0;

// pi, for the sources that need it as a constant (C++17 has no
// std::numbers); a source takes it with `using constants::kPi;`, which,
// unlike a definition of its own, may appear in several sources compiled
// as one translation unit (a unity build)
namespace constants {
inline constexpr double kPi = 3.14159265358979323846;
}  // namespace constants

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_TYPES_H_
