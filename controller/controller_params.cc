#include "controller/controller_params.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace vmh {
namespace {

using constants::kPi;

void require(bool ok, const std::string& field, const std::string& what) {
  if (!ok) {
    throw std::invalid_argument("controller parameter " + field + ": " + what);
  }
}

bool all_finite_nonnegative(const Vec6& v) {
  return v.allFinite() && (v.array() >= 0.0).all();
}

}  // namespace

const char* error_formulation_name(ErrorFormulation f) {
  return f == ErrorFormulation::kThesis ? "thesis" : "geometric";
}

bool parse_error_formulation(const char* text, ErrorFormulation* f) {
  if (std::strcmp(text, "thesis") == 0) {
    *f = ErrorFormulation::kThesis;
    return true;
  }
  if (std::strcmp(text, "geometric") == 0) {
    *f = ErrorFormulation::kGeometric;
    return true;
  }
  return false;
}

const char* placement_method_name(PlacementMethod m) {
  return m == PlacementMethod::kGaussNewton ? "gauss-newton" : "closed";
}

bool parse_placement_method(const char* text, PlacementMethod* m) {
  if (std::strcmp(text, "gauss-newton") == 0) {
    *m = PlacementMethod::kGaussNewton;
    return true;
  }
  if (std::strcmp(text, "closed") == 0) {
    *m = PlacementMethod::kClosedForm;
    return true;
  }
  return false;
}

double thesis_orientation_gain(double multiple_N_per_mm, double length_mm) {
  return multiple_N_per_mm * 2.0 * kPi * length_mm;
}

void ControllerParams::validate() const {
  omni.validate();
  require(vm.pivot_mm.allFinite(), "vm.pivot_mm", "must be finite");
  require(vm.R_pivot.allFinite() &&
              (vm.R_pivot.transpose() * vm.R_pivot).isIdentity(1e-9) &&
              std::abs(vm.R_pivot.determinant() - 1.0) < 1e-9,
          "vm.R_pivot", "must be a rotation matrix");
  require(std::isfinite(vm.length_mm) && vm.length_mm > 0.0, "vm.length_mm",
          "must be finite and > 0");
  require(!std::isnan(vm.friction_mu) && vm.friction_mu >= 0.0,
          "vm.friction_mu", "must be >= 0 (inf: never slides)");
  const double gains_list[] = {gains.k_pos_N_per_mm, gains.k_ornt_Nmm_per_rad,
                               gains.k_vel_Ns_per_mm,
                               gains.k_vel_ornt_Nmms_per_rad};
  const char* gain_names[] = {"gains.k_pos_N_per_mm",
                              "gains.k_ornt_Nmm_per_rad",
                              "gains.k_vel_Ns_per_mm",
                              "gains.k_vel_ornt_Nmms_per_rad"};
  for (int i = 0; i < 4; ++i) {
    require(std::isfinite(gains_list[i]) && gains_list[i] >= 0.0,
            gain_names[i], "must be finite and >= 0");
  }
  require(all_finite_nonnegative(placement_options.weights),
          "placement_options.weights", "must be finite and >= 0");
  require(placement_options.weights.sum() > 0.0, "placement_options.weights",
          "must not all be zero");
  require(std::isfinite(placement_options.tolerance) &&
              placement_options.tolerance > 0.0,
          "placement_options.tolerance", "must be finite and > 0");
  require(placement_options.max_iterations >= 1,
          "placement_options.max_iterations", "must be >= 1");
  require(std::isfinite(placement_options.relative_damping) &&
              placement_options.relative_damping >= 0.0,
          "placement_options.relative_damping", "must be finite and >= 0");
  require(projection_weights.allFinite() &&
              (projection_weights.array() > 0.0).all(),
          "projection_weights", "must be finite and > 0");
  require(std::isfinite(length_unit_mm) && length_unit_mm > 0.0,
          "length_unit_mm", "must be finite and > 0");
  require(std::isfinite(servo_period_s) && servo_period_s > 0.0,
          "servo_period_s", "must be finite and > 0");
  require(std::isfinite(velocity_cutoff_Hz), "velocity_cutoff_Hz",
          "must be finite (<= 0 turns the filter off)");
  require(std::isfinite(singular_rcond) && singular_rcond > 0.0 &&
              singular_rcond < 1.0,
          "singular_rcond", "must be in (0, 1)");
  require(std::isfinite(singular_damping) && singular_damping >= 0.0,
          "singular_damping", "must be finite and >= 0");
  // the saturation compares |F|^2 with the limit's square, which underflows
  // for a limit below ~1e-154 N and let a larger force through (found by
  // tests/fuzz/controller_tick_fuzz.cc); 1 uN is far below any haptic
  // device's resolution
  require(std::isfinite(force_limit_N) && force_limit_N >= kMinForceLimit_N,
          "force_limit_N", "must be finite and >= 1e-6");
}

}  // namespace vmh
