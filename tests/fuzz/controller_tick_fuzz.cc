// libFuzzer harness: vmh::Controller::tick (controller/controller.h).
//
// The input chooses the controller's parameters (VM kind, pivot, length,
// gains, formulation, placement, unit, force limit, ...) and then a run of
// ticks, each a six-joint reading that may be any double: NaN, inf,
// subnormals, 1e308 and ordinary angles. Parameters the constructor refuses
// must be refused with std::invalid_argument. Every tick must:
//  - return the status it stores, with only the documented bits set, each
//    named by status_flag_name() from the documented set;
//  - on a fault (invalid_input, numerical_fault): command zero force and
//    zero torques;
//  - otherwise command a finite force no larger than force_limit_N and
//    finite motor torques within OmniParams' motor limits;
//  - flag a non-finite joint angle as invalid_input.
#include <fuzzer/FuzzedDataProvider.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>

#include "controller/controller.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

// a double the way a hostile caller would give one
double any_double(FuzzedDataProvider& in, double lo, double hi) {
  static const double kSpecial[] = {
      0.0, -0.0, 1.0, -1.0, 1e-320, -1e-320, 1e-12, 1e308, -1e308, 1e155,
      -1e155, 1e153, 1e17, -1e17, 3e6, 1e6,
      std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity(),
      std::numeric_limits<double>::quiet_NaN(),
      std::numeric_limits<double>::denorm_min(),
      std::numeric_limits<double>::max()};
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return in.PickValueInArray(kSpecial);
    case 1: {
      const auto bits = in.ConsumeIntegral<std::uint64_t>();
      double d;
      std::memcpy(&d, &bits, sizeof d);
      return d;
    }
    default:
      return in.ConsumeFloatingPointInRange(lo, hi);
  }
}

std::string describe(const vmh::ControllerParams& p, const vmh::Joints& q,
                     const vmh::ControlOutput& o) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "vm %d pivot %g %g %g L %g kpos %g kornt %g flimit %g unit %g "
                "q %g %g %g %g %g %g status 0x%x F %g %g %g tau %g %g %g",
                static_cast<int>(p.vm.kind), p.vm.pivot_mm.x(),
                p.vm.pivot_mm.y(), p.vm.pivot_mm.z(), p.vm.length_mm,
                p.gains.k_pos_N_per_mm, p.gains.k_ornt_Nmm_per_rad,
                p.force_limit_N, p.length_unit_mm, q[0], q[1], q[2], q[3],
                q[4], q[5], o.status, o.force_device_N.x(),
                o.force_device_N.y(), o.force_device_N.z(), o.tau_motor_Nm.x(),
                o.tau_motor_Nm.y(), o.tau_motor_Nm.z());
  return buf;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  using namespace vmh;
  FuzzedDataProvider in(data, size);

  ControllerParams p;
  // any registered mechanism
  const int kinds = static_cast<int>(vm_registry().size());
  p.vm.kind = vm_registry()[static_cast<std::size_t>(
                                in.ConsumeIntegralInRange<int>(0, kinds - 1))]
                  .kind;
  for (int i = 0; i < 3; ++i) p.vm.pivot_mm[i] = any_double(in, -200, 200);
  if (in.ConsumeBool()) {
    // a rotated pivot frame (a proper rotation from an angle-axis)
    Vec3 axis(in.ConsumeFloatingPointInRange(-1.0, 1.0),
              in.ConsumeFloatingPointInRange(-1.0, 1.0), 1.0);
    p.vm.R_pivot = Eigen::AngleAxisd(in.ConsumeFloatingPointInRange(-4.0, 4.0),
                                     axis.normalized())
                       .toRotationMatrix();
  }
  p.vm.length_mm = any_double(in, 0, 200);
  p.vm.friction_mu = any_double(in, 0, 2);
  p.vm.unilateral = in.ConsumeBool();
  p.gains.k_pos_N_per_mm = any_double(in, 0, 5);
  p.gains.k_ornt_Nmm_per_rad = any_double(in, 0, 500);
  p.gains.k_vel_Ns_per_mm = in.ConsumeBool() ? any_double(in, 0, 0.1) : 0.0;
  p.gains.k_vel_ornt_Nmms_per_rad =
      in.ConsumeBool() ? any_double(in, 0, 10) : 0.0;
  p.error = in.ConsumeBool() ? ErrorFormulation::kThesis
                             : ErrorFormulation::kGeometric;
  p.placement = in.ConsumeBool() ? PlacementMethod::kGaussNewton
                                 : PlacementMethod::kClosedForm;
  if (in.ConsumeBool()) p.length_unit_mm = any_double(in, 0.1, 1000);
  if (in.ConsumeBool()) p.servo_period_s = any_double(in, 1e-5, 1e-2);
  if (in.ConsumeBool()) p.velocity_cutoff_Hz = any_double(in, 0, 1000);
  if (in.ConsumeBool()) p.force_limit_N = any_double(in, 0, 10);
  if (in.ConsumeBool()) {
    for (int i = 0; i < 6; ++i) p.projection_weights[i] = any_double(in, 0, 10);
  }

  std::unique_ptr<Controller> c;
  try {
    c = std::make_unique<Controller>(p);
  } catch (const std::invalid_argument& e) {
    FUZZ_CHECK(std::strlen(e.what()) > 0, "empty invalid_argument message");
    return 0;
  }
  // the constructor's promise: what it accepts is within these
  const ControllerParams& q_params = c->params();
  FUZZ_CHECK(std::isfinite(q_params.force_limit_N) &&
                 q_params.force_limit_N >= 0.0,
             "accepted a force limit that is not finite and >= 0");

  static const std::set<std::string> kNames = {
      "ok",          "invalid_input",           "numerical_fault",
      "outside_joint_limits", "vm_singular",   "placement_not_converged",
      "rm_at_pivot", "orientation_degenerate",  "force_saturated",
      "torque_saturated", "contact_sliding",    "contact_open"};
  constexpr ControlStatus kAllBits = (1u << kStatusFlagCount) - 1u;
  const double F_limit = q_params.force_limit_N;
  const auto& tau_limit = q_params.omni.motor_torque_limit_Nm;

  ControlOutput out;
  const int ticks = in.ConsumeIntegralInRange<int>(1, 16);
  for (int t = 0; t < ticks && in.remaining_bytes() > 0; ++t) {
    Joints q;
    for (int i = 0; i < 6; ++i) q[i] = any_double(in, -3.5, 3.5);
    if (in.ConsumeBool()) c->reset();
    const ControlStatus st = c->tick(q, &out);
    const std::string ctx = describe(q_params, q, out);

    FUZZ_CHECK(st == out.status, ctx);
    FUZZ_CHECK((st & ~kAllBits) == 0u, "status has an undocumented bit: " + ctx);
    FUZZ_CHECK(status_flag_name(kStatusOk) != nullptr &&
                   std::string(status_flag_name(kStatusOk)) == "ok",
               ctx);
    for (int b = 0; b < kStatusFlagCount; ++b) {
      const ControlStatus bit = 1u << b;
      if ((st & bit) == 0u) continue;
      const char* name = status_flag_name(bit);
      FUZZ_CHECK(name != nullptr && kNames.count(name) == 1,
                 "status bit without a valid name: " + ctx);
    }
    if (!q.allFinite()) {
      FUZZ_CHECK((st & kStatusInvalidInput) != 0u,
                 "non-finite joints not flagged invalid_input: " + ctx);
    }
    if (is_fault(st)) {
      FUZZ_CHECK(out.force_device_N.isZero(0.0) && out.force_base_N.isZero(0.0) &&
                     out.tau_dh_Nm.isZero(0.0) && out.tau_motor_Nm.isZero(0.0),
                 "a fault with a non-zero command: " + ctx);
      continue;
    }
    FUZZ_CHECK(out.force_device_N.allFinite() && out.force_base_N.allFinite() &&
                   out.tau_dh_Nm.allFinite() && out.tau_motor_Nm.allFinite(),
               "non-finite command without a fault: " + ctx);
    // 1e-12 relative: the saturation's own rounding
    FUZZ_CHECK(out.force_device_N.norm() <= F_limit * (1.0 + 1e-12) + 1e-300,
               "force over force_limit_N: " + ctx);
    FUZZ_CHECK(std::abs(out.force_base_N.norm() - out.force_device_N.norm()) <=
                   1e-9 * (1.0 + out.force_device_N.norm()),
               "device and base forces differ in size: " + ctx);
    for (int i = 0; i < 3; ++i) {
      const double lim = tau_limit[static_cast<std::size_t>(i)];
      FUZZ_CHECK(std::abs(out.tau_motor_Nm[i]) <= lim * (1.0 + 1e-12),
                 "motor torque over its limit: " + ctx);
    }
  }
  return 0;
}
