#include "controller/omni_kinematics.h"

#include <cmath>

#include "controller/trig.h"

namespace vmh {

namespace {

using vmh::constants::kPi;
constexpr double kHalfPi = 0.5 * kPi;

// below this horizontal distance (m) the wrist centre is taken to be on the
// joint-1 axis
constexpr double kAxisEpsM = 1e-12;
// |cos q5| below this is the gimbal singularity
constexpr double kWristEps = 1e-12;
// |sin q3| may exceed 1 by this much from rounding on the reach boundary
constexpr double kReachSlack = 1e-12;
// solutions closer than this (rad, every joint) are the same solution
constexpr double kSameSolutionRad = 1e-9;

// angle a shifted by whole turns to lie within pi of ref
double unwrap_near(double a, double ref) { return ref + wrap_angle(a - ref); }

bool same_solution(const Joints& a, const Joints& b) {
  for (int i = 0; i < kOmniJoints; ++i) {
    if (std::abs(wrap_angle(a[i] - b[i])) > kSameSolutionRad) return false;
  }
  return true;
}

// appends q unless an equal solution is already there
void push_unique(const OmniParams& params, const Joints& q, IkSolutions* out) {
  for (int k = 0; k < out->count; ++k) {
    if (same_solution(out->q_dh[k], q)) return;
  }
  if (out->count >= IkSolutions::kMax) return;
  out->q_dh[out->count] = q;
  out->within_limits[out->count] = omni_within_limits(params, q);
  ++out->count;
}

}  // namespace

double wrap_angle_out_of_range(double a) {
  // wrap_angle (inline) has returned an angle already in range; NaN fails
  // its comparisons and passes through below
  if (a > -kPi && a <= kPi) return a;
  // one turn off (a difference of two wrapped angles): subtracting 2 pi is
  // exact there (Sterbenz) and is what remainder() returns, without its call
  if (a > kPi && a < 2.5 * kPi) return a - 2.0 * kPi;
  if (a <= -kPi && a > -2.5 * kPi) return a + 2.0 * kPi;
  if (!std::isfinite(a)) return a;
  // remainder() gives [-pi, pi]; move -pi to +pi for a half-open range
  double w = std::remainder(a, 2.0 * kPi);
  if (w <= -kPi) w += 2.0 * kPi;
  return w;
}

bool omni_within_limits(const OmniParams& params, const Joints& q) {
  for (int i = 0; i < kOmniJoints; ++i) {
    const double a = wrap_angle(q[i]);
    if (!(a >= params.joint_lower_rad[i] && a <= params.joint_upper_rad[i])) {
      return false;
    }
  }
  return true;
}

std::array<DhRow, kOmniJoints> omni_dh_table(const OmniParams& p) {
  // Table B.1: a_{i-1}, alpha_{i-1}, d_i, theta_i offset
  return {{
      {0.0, 0.0, p.l0_m, 0.0},
      {0.0, kHalfPi, 0.0, 0.0},
      {p.l1_m, 0.0, 0.0, 0.0},
      {0.0, kHalfPi, p.l2_m, 0.0},
      {0.0, -kHalfPi, 0.0, -kHalfPi},
      {0.0, -kHalfPi, 0.0, kHalfPi},
  }};
}

Eigen::Isometry3d dh_transform(const DhRow& row, double q) {
  const double th = q + row.theta_offset_rad;
  const double ct = std::cos(th), st = std::sin(th);
  const double ca = std::cos(row.alpha_rad), sa = std::sin(row.alpha_rad);
  Eigen::Isometry3d T;
  Eigen::Matrix3d R;
  R << ct, -st, 0.0,          //
      st * ca, ct * ca, -sa,  //
      st * sa, ct * sa, ca;
  T.linear() = R;
  T.translation() << row.a_m, -sa * row.d_m, ca * row.d_m;
  T.makeAffine();
  return T;
}

void omni_frames(const OmniParams& params, const Joints& q,
                 OmniFrames* frames) {
  const std::array<DhRow, kOmniJoints> table = omni_dh_table(params);
  frames->T_base[0].setIdentity();
  for (int i = 0; i < kOmniJoints; ++i) {
    frames->T_base[i + 1] = frames->T_base[i] * dh_transform(table[i], q[i]);
  }
}

OmniPose omni_fk(const OmniParams& params, const Joints& q) {
  OmniFrames f;
  omni_frames(params, q, &f);
  return {f.T_base[kOmniJoints].translation(), f.T_base[kOmniJoints].linear()};
}

Vec3 omni_tool_point(const OmniParams& params, const OmniPose& pose) {
  return pose.p_base_m + params.tool_offset_m * pose.R_base.col(2);
}

Mat6 omni_jacobian_at(const OmniParams& params, const Joints& q,
                      double offset_m) {
  OmniFrames f;
  omni_frames(params, q, &f);
  const Eigen::Isometry3d& T6 = f.T_base[kOmniJoints];
  const Vec3 p = T6.translation() + offset_m * T6.linear().col(2);
  Mat6 J;
  // column i: joint i turns about z of frame i through the origin of frame i
  for (int i = 0; i < kOmniJoints; ++i) {
    const Vec3 z = f.T_base[i + 1].linear().col(2);
    const Vec3 o = f.T_base[i + 1].translation();
    J.block<3, 1>(0, i) = z.cross(p - o);
    J.block<3, 1>(3, i) = z;
  }
  return J;
}

Mat6 omni_jacobian(const OmniParams& params, const Joints& q) {
  return omni_jacobian_at(params, q, 0.0);
}

namespace {

// The chain of Table B.1 in closed form. With c_i = cos q_i, s_i = sin q_i
// and q23 = q2 + q3, composing RotX(alpha) RotZ(theta) for alpha in
// {0, +-pi/2} only permutes and negates columns, so every frame axis is a
// short sum of the previous frame's axes:
//   z1 = (0, 0, 1),  z2 = z3 = (s1, -c1, 0),
//   x3 = (c1 c23, s1 c23, s23), y3 = (-c1 s23, -s1 s23, c23),
//   z4 = -y3,  x4 = c4 x3 + s4 z3,  y4 = -s4 x3 + c4 z3,
//   (theta5 = q5 - pi/2)  x5 = s5 x4 + c5 z4,  y5 = c5 x4 - s5 z4,  z5 = y4,
//   (theta6 = q6 + pi/2)  x6 = -s6 x5 - c6 z5,  y6 = -c6 x5 + s6 z5,  z6 = y5,
// and the origins o1 = o2 = (0, 0, l0), o3 = o2 + l1 x2 with
// x2 = (c1 c2, s1 c2, s2), o4 = o5 = o6 = o3 - l2 y3 (the wrist centre).
struct ClosedChain {
  double c1, s1;
  Vec3 z2, x3, y3, z4;  // y3, z4: forearm; x3: elbow
  Vec3 o1, o3, p;       // joint-1/2 origin, elbow, wrist centre
};

ClosedChain arm_chain(const OmniParams& params, const Joints& q) {
  ClosedChain k;
  const SinCos t1 = sin_cos(q[0]), t2 = sin_cos(q[1]),
               t23 = sin_cos(q[1] + q[2]);
  k.c1 = t1.c;
  k.s1 = t1.s;
  const double c2 = t2.c, s2 = t2.s;
  const double c23 = t23.c, s23 = t23.s;
  const double c1 = k.c1, s1 = k.s1;
  k.z2 = Vec3(s1, -c1, 0.0);
  k.x3 = Vec3(c1 * c23, s1 * c23, s23);
  k.y3 = Vec3(-c1 * s23, -s1 * s23, c23);
  k.z4 = -k.y3;
  k.o1 = Vec3(0.0, 0.0, params.l0_m);
  k.o3 = k.o1 + params.l1_m * Vec3(c1 * c2, s1 * c2, s2);
  k.p = k.o3 - params.l2_m * k.y3;
  return k;
}

}  // namespace

void omni_fk_jacobian(const OmniParams& params, const Joints& q,
                      OmniPose* pose, Mat6* J, double offset_m) {
  const ClosedChain k = arm_chain(params, q);
  const SinCos t4 = sin_cos(q[3]), t5 = sin_cos(q[4]), t6 = sin_cos(q[5]);
  const double c4 = t4.c, s4 = t4.s;
  const double c5 = t5.c, s5 = t5.s;
  const double c6 = t6.c, s6 = t6.s;
  const Vec3& z3 = k.z2;
  const Vec3 x4 = c4 * k.x3 + s4 * z3;
  const Vec3 y4 = -s4 * k.x3 + c4 * z3;
  const Vec3 x5 = s5 * x4 + c5 * k.z4;
  const Vec3 y5 = c5 * x4 - s5 * k.z4;
  const Vec3& z5 = y4;
  const Vec3& z6 = y5;
  if (pose != nullptr) {
    pose->p_base_m = k.p;
    pose->R_base.col(0) = -s6 * x5 - c6 * z5;
    pose->R_base.col(1) = -c6 * x5 + s6 * z5;
    pose->R_base.col(2) = z6;
  }
  if (J == nullptr) return;
  const Vec3 pt = k.p + offset_m * z6;
  const Vec3 r1 = pt - k.o1;  // o1 = o2
  const Vec3 r3 = pt - k.o3;
  const Vec3 rw = offset_m * z6;  // pt - o4 (= o5 = o6)
  J->block<3, 1>(0, 0) = Vec3(-r1.y(), r1.x(), 0.0);  // z1 x r1
  J->block<3, 1>(0, 1) = k.z2.cross(r1);
  J->block<3, 1>(0, 2) = z3.cross(r3);
  J->block<3, 1>(0, 3) = k.z4.cross(rw);
  J->block<3, 1>(0, 4) = z5.cross(rw);
  J->block<3, 1>(0, 5) = z6.cross(rw);
  J->block<3, 1>(3, 0) = Vec3::UnitZ();
  J->block<3, 1>(3, 1) = k.z2;
  J->block<3, 1>(3, 2) = z3;
  J->block<3, 1>(3, 3) = k.z4;
  J->block<3, 1>(3, 4) = z5;
  J->block<3, 1>(3, 5) = z6;
}

OmniArmKinematics omni_arm_kinematics(const OmniParams& params,
                                      const Joints& q) {
  const ClosedChain k = arm_chain(params, q);
  const SinCos t4 = sin_cos(q[3]), t5 = sin_cos(q[4]);
  const double c4 = t4.c, s4 = t4.s;
  const double c5 = t5.c, s5 = t5.s;
  OmniArmKinematics out;
  out.p_base_m = k.p;
  // z6 = y5 = c5 x4 - s5 z4 with x4 = c4 x3 + s4 z3
  out.z6_base = c5 * (c4 * k.x3 + s4 * k.z2) - s5 * k.z4;
  const Vec3 r1 = k.p - k.o1;
  const Vec3 r3 = k.p - k.o3;
  out.Jv_arm.col(0) = Vec3(-r1.y(), r1.x(), 0.0);
  out.Jv_arm.col(1) = k.z2.cross(r1);
  out.Jv_arm.col(2) = k.z2.cross(r3);
  return out;
}

const char* ik_status_name(IkStatus s) {
  switch (s) {
    case IkStatus::kOk:
      return "ok";
    case IkStatus::kUnreachable:
      return "unreachable";
    case IkStatus::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

IkSolutions omni_ik_position(const OmniParams& params, const Vec3& p,
                             const Joints& near) {
  IkSolutions out;
  if (!p.allFinite() || !near.allFinite() ||
      near.cwiseAbs().maxCoeff() > kIkMaxHintRad) {
    out.status = IkStatus::kInvalidInput;
    return out;
  }
  const double l1 = params.l1_m, l2 = params.l2_m;
  // the wrist centre is (rho c1, rho s1, l0 + zr) with
  //   rho = c2 (l1 + l2 s3) + s2 l2 c3   (signed reach from the joint-1 axis)
  //   zr  = s2 (l1 + l2 s3) - c2 l2 c3   (eq. B.14)
  // so rho^2 + zr^2 = l1^2 + l2^2 + 2 l1 l2 s3 fixes q3 (two branches), and
  // q2 follows from a rotation by q2 of (l1 + l2 s3, -l2 c3).
  const double rho_abs = std::hypot(p.x(), p.y());
  const double zr = p.z() - params.l0_m;
  const double r = std::hypot(rho_abs, zr);
  const double s3 = (r * r - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
  if (std::abs(s3) > 1.0 + kReachSlack) {
    out.status = IkStatus::kUnreachable;
    out.reach_excess_m = (r > l1 + l2) ? r - (l1 + l2) : std::abs(l1 - l2) - r;
    return out;
  }
  const double s3c = std::max(-1.0, std::min(1.0, s3));
  const double q3a = std::asin(s3c);
  const double q3_branches[2] = {q3a, kPi - q3a};
  out.elbow_singular = std::abs(std::abs(s3c) - 1.0) < 1e-12;

  double q1_branches[2];
  double rho_branches[2];
  int n_shoulder = 2;
  if (rho_abs > kAxisEpsM) {
    q1_branches[0] = std::atan2(p.y(), p.x());
    rho_branches[0] = rho_abs;
    q1_branches[1] = std::atan2(-p.y(), -p.x());
    rho_branches[1] = -rho_abs;
  } else {
    out.shoulder_singular = true;
    q1_branches[0] = near[0];
    rho_branches[0] = 0.0;
    n_shoulder = 1;
  }

  for (int i = 0; i < n_shoulder; ++i) {
    for (double q3 : q3_branches) {
      const double a = l1 + l2 * std::sin(q3);
      const double b = l2 * std::cos(q3);
      const double rho = rho_branches[i];
      double q2;
      if (a * a + b * b > kAxisEpsM * kAxisEpsM) {
        q2 = std::atan2(b * rho + a * zr, a * rho - b * zr);
      } else {
        // wrist centre at the shoulder (possible only when l1 = l2): q2 free
        out.shoulder_singular = true;
        q2 = near[1];
      }
      Joints q = near;
      q[0] = unwrap_near(q1_branches[i], near[0]);
      q[1] = unwrap_near(q2, near[1]);
      q[2] = unwrap_near(q3, near[2]);
      push_unique(params, q, &out);
    }
  }
  out.status = IkStatus::kOk;
  return out;
}

int omni_wrist_angles(const OmniParams& params, const Eigen::Vector3d& q123,
                      const Mat3& R_base, double q4_hint,
                      std::array<Eigen::Vector3d, 2>* q456, bool* singular) {
  *singular = false;
  if (!q123.allFinite() || !R_base.allFinite() || !std::isfinite(q4_hint)) {
    return 0;
  }
  // only the arm links 1-3 are needed for R_03
  const std::array<DhRow, kOmniJoints> table = omni_dh_table(params);
  const Mat3 R03 =
      (dh_transform(table[0], q123[0]) * dh_transform(table[1], q123[1]) *
       dh_transform(table[2], q123[2]))
          .linear();
  // R_36 = R_03^T R_06 has the structure of eq. B.12:
  //   col 3 = (c4 c5, s5, s4 c5), row 2 = (c5 s6, c5 c6, s5)
  const Mat3 R36 = R03.transpose() * R_base;
  const double s5 = std::max(-1.0, std::min(1.0, R36(1, 2)));
  const double c5_abs = std::hypot(R36(0, 2), R36(2, 2));
  if (c5_abs > kWristEps) {
    for (int k = 0; k < 2; ++k) {
      const double sign = (k == 0) ? 1.0 : -1.0;
      const double q5 = std::atan2(s5, sign * c5_abs);
      const double q4 = std::atan2(sign * R36(2, 2), sign * R36(0, 2));
      const double q6 = std::atan2(sign * R36(1, 0), sign * R36(1, 1));
      (*q456)[k] << q4, q5, q6;
    }
    return 2;
  }
  // gimbal singularity, c5 = 0. Column 1 of R_36 is then
  //   s5 = +1: (sin(q4 - q6), 0, -cos(q4 - q6))
  //   s5 = -1: (sin(q4 + q6), 0, -cos(q4 + q6))
  *singular = true;
  const double phi = std::atan2(R36(0, 0), -R36(2, 0));
  const double q4 = q4_hint;
  if (s5 > 0) {
    (*q456)[0] << q4, kHalfPi, wrap_angle(q4 - phi);
  } else {
    (*q456)[0] << q4, -kHalfPi, wrap_angle(phi - q4);
  }
  return 1;
}

IkSolutions omni_ik_pose(const OmniParams& params, const Vec3& p,
                         const Mat3& R_base, const Joints& near) {
  IkSolutions arm = omni_ik_position(params, p, near);
  if (arm.status != IkStatus::kOk) return arm;
  if (!R_base.allFinite()) {
    arm.count = 0;
    arm.status = IkStatus::kInvalidInput;
    return arm;
  }
  IkSolutions out;
  out.status = IkStatus::kOk;
  out.shoulder_singular = arm.shoulder_singular;
  out.elbow_singular = arm.elbow_singular;
  for (int i = 0; i < arm.count; ++i) {
    std::array<Eigen::Vector3d, 2> q456;
    bool singular = false;
    const int n = omni_wrist_angles(params, arm.q_dh[i].head<3>(), R_base,
                                    near[3], &q456, &singular);
    out.wrist_singular = out.wrist_singular || singular;
    for (int k = 0; k < n; ++k) {
      Joints q = arm.q_dh[i];
      for (int j = 0; j < 3; ++j)
        q[3 + j] = unwrap_near(q456[k][j], near[3 + j]);
      push_unique(params, q, &out);
    }
  }
  return out;
}

int omni_ik_nearest(const IkSolutions& s, const Joints& near) {
  int best = -1;
  double best_d2 = 0.0;
  for (int k = 0; k < s.count; ++k) {
    double d2 = 0.0;
    for (int i = 0; i < kOmniJoints; ++i) {
      const double d = wrap_angle(s.q_dh[k][i] - near[i]);
      d2 += d * d;
    }
    if (best < 0 || d2 < best_d2) {
      best = k;
      best_d2 = d2;
    }
  }
  return best;
}

}  // namespace vmh
