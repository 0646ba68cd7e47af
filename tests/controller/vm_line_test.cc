// The line slider (controller/vm_line.h) against closed forms: the law's
// force on it is K_pos times the offset, normal to the line, whatever the
// stylus does; and it is the circle VM's limit as the circle's radius grows,
// the gap closing as the circle's bending force K_o e_o L / (w_p L^2 + w_o)
// does, like 1 / radius.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "controller/controller.h"
#include "controller/vm_line.h"
#include "tests/support/random_joints.h"

namespace vmh {
namespace {

constexpr double kKpos_N_per_mm = 0.5;
constexpr double kOffset_mm = 3.0;

// The wrist centre and stylus of the Omni at q (device frame, mm), from a
// controller's first tick (any VM)
ControlOutput rm_at(const Joints& q) {
  Controller c{ControllerParams{}};
  ControlOutput out;
  c.tick(q, &out);
  return out;
}

// gains of thesis case 2 (K_ornt = 0.5 x 2 pi 50 N mm/rad), no damping, no
// limits in the way, a VM of `kind` through origin with the given length
ControllerParams params(VmKind kind, const Vec3& pivot_mm, double length_mm,
                        ErrorFormulation error) {
  ControllerParams p;
  p.vm.kind = kind;
  p.vm.pivot_mm = pivot_mm;
  p.vm.length_mm = length_mm;
  p.error = error;
  p.gains.k_pos_N_per_mm = kKpos_N_per_mm;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  p.force_limit_N = 100.0;
  for (double& lim : p.omni.motor_torque_limit_Nm) lim = 1e3;
  return p;
}

// poses inside the Omni's joint ranges
std::vector<Joints> poses() {
  testing::JointSampler sampler(71);
  std::vector<Joints> out;
  for (int k = 0; k < 40; ++k) out.push_back(sampler.next_within(OmniParams()));
  return out;
}

// Off the line by kOffset_mm along the pivot frame's x: the force is
// K_pos kOffset_mm toward the line, nothing along it, with the stylus
// however it is (a misalignment the line cannot turn to meet is not felt)
TEST(LineVm, ForceIsTheSpringToTheLineAloneWhateverTheStylus) {
  for (ErrorFormulation error :
       {ErrorFormulation::kThesis, ErrorFormulation::kGeometric}) {
    for (const Joints& q : poses()) {
      const ControlOutput rm = rm_at(q);
      const Vec3 origin = rm.p_rm_mm + kOffset_mm * Vec3::UnitX();
      Controller c(params(VmKind::kLine, origin, 50.0, error));
      ControlOutput out;
      c.tick(q, &out);
      ASSERT_FALSE(is_fault(out.status));
      const Vec3 F = out.force_device_N;
      EXPECT_NEAR(F.x(), kKpos_N_per_mm * kOffset_mm, 1e-9);
      EXPECT_NEAR(F.y(), 0.0, 1e-12);  // along the line
      EXPECT_NEAR(F.z(), 0.0, 1e-12);
      EXPECT_LE((out.x_v_mm - (rm.p_rm_mm + kOffset_mm * Vec3::UnitX()))
                    .norm(),
                1e-9);
      EXPECT_LE((out.x_r_mm - out.x_v_mm).norm(), 0.0);
    }
  }
}

// The circle of radius rho centred at origin - rho x is, at the origin, the
// line: same point, tangent and link. Its force differs from the line's by
// its bending term, f_t = K_o e_o rho / (rho^2 + 1) along the tangent (the
// weights one, mm). The RM stands on the circle's radius through the common
// point, so both nearest points are that point and the position parts agree:
// the gap is the bending term alone.
TEST(LineVm, IsTheCirclesLimitAsTheRadiusGrows) {
  int tried = 0;
  for (const Joints& q : poses()) {
    const ControlOutput rm = rm_at(q);
    const Vec3 origin = rm.p_rm_mm + kOffset_mm * Vec3::UnitX();
    Controller line(
        params(VmKind::kLine, origin, 50.0, ErrorFormulation::kGeometric));
    ControlOutput fl;
    line.tick(q, &fl);
    // the line's own (geometric) error: the stylus's angle about z from x
    const double e_o = std::abs(fl.e[5]);
    if (e_o < 0.05 || e_o > 3.0) continue;  // too small to see, or wrapping
    ++tried;
    const double K_o = thesis_orientation_gain(0.5, 50.0);
    for (double rho : {1e3, 1e4, 1e5}) {
      Controller circle(params(VmKind::kCircle,
                               origin - rho * Vec3::UnitX(), rho,
                               ErrorFormulation::kGeometric));
      ControlOutput fc;
      circle.tick(q, &fc);
      const double gap = (fc.force_device_N - fl.force_device_N).norm();
      const double bending = K_o * e_o * rho / (rho * rho + 1.0);
      // measured: equal to six digits from rho = 1e3 mm on
      EXPECT_NEAR(gap, bending, 1e-3 * bending + 1e-7)
          << "rho " << rho << " e_o " << e_o;
    }
  }
  EXPECT_GE(tried, 10);
}

}  // namespace
}  // namespace vmh
