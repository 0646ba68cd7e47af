// The controller's parameters (controller/controller.h runs them): where
// the virtual mechanism is and what it is (VmParams), the gains of eq.
// 3.8/3.28 (Gains), the error formulation, the placement, the projection's
// weights and regularisation, the force and torque limits, the servo
// period. Device frame, mm, as each name says. validate() throws
// std::invalid_argument naming the field; nothing here runs in the tick.
#ifndef VMHAPTICS_CONTROLLER_CONTROLLER_PARAMS_H_
#define VMHAPTICS_CONTROLLER_CONTROLLER_PARAMS_H_

#include "controller/control_law.h"
#include "controller/omni_params.h"
#include "controller/virtual_mechanism.h"
#include "controller/vm_registry.h"

namespace vmh {

enum class ErrorFormulation {
  // eq. 3.32-3.37: orientation rows are wrapped differences of VM angles
  // (theta_V - theta_R), as in the thesis and Appendix D
  kThesis,
  // orientation rows are the rotation vector from the stylus axis to the
  // VM's link axis, the quantity J_V's angular-velocity rows act on
  kGeometric,
};
const char* error_formulation_name(ErrorFormulation f);  // thesis, geometric
bool parse_error_formulation(const char* text, ErrorFormulation* f);

enum class PlacementMethod {
  kGaussNewton,  // eq. 3.15-3.16 with PlacementOptions::weights
  kClosedForm,   // nearest point (circle, sphere); see SurfaceVm
};
const char* placement_method_name(PlacementMethod m);  // gauss-newton, closed
bool parse_placement_method(const char* text, PlacementMethod* m);

// Where the VM is and what it is. Device frame, mm.
struct VmParams {
  VmKind kind = VmKind::kCircle;
  // the pivot (circle, sphere) or a point of the plane (surface); Appendix D
  // puts it at the device-frame origin
  Vec3 pivot_mm = Vec3::Zero();
  // pivot frame in the device frame: circle plane = its x-y plane, sphere
  // pole axis = its -z, surface normal = its z
  Mat3 R_pivot = Mat3::Identity();
  double length_mm = 50.0;  // Lv in listing D.1
  // surface only: Coulomb coefficient of the contact point. 0 slides freely
  // (the 5-DOF VM of §3.1); > 0 sticks until |f_t| > mu f_n; +inf never
  // slides
  double friction_mu = 0.0;
  // surface only: the probe may lift off (no pulling force) instead of being
  // held on the plane
  bool unilateral = false;
};

// K_p and K_v of eq. 3.8/3.28, in physical units.
struct Gains {
  double k_pos_N_per_mm = 0.5;  // cases 1, 2, 4, 5, 6
  // orientation stiffness; eq. 3.28 sets it to a multiple of the
  // circumference 2 pi L (see thesis_orientation_gain)
  double k_ornt_Nmm_per_rad = 0.0;
  double k_vel_Ns_per_mm = 0.0;        // the thesis runs with e_dot = 0
  double k_vel_ornt_Nmms_per_rad = 0.0;
};

// eq. 3.28: K_ornt = multiple x 2 pi L. The thesis's cases use multiples
// 0, 0.5 and 1 (docs/sources.md §2) with L = 50 mm; the multiple carries the
// position gain's unit, N/mm, so K_ornt is in N mm/rad.
double thesis_orientation_gain(double multiple_N_per_mm, double length_mm);

// The smallest force limit ControllerParams::validate accepts (N): below
// ~1e-154 N the limit's square underflows and the saturation could not hold
// it.
inline constexpr double kMinForceLimit_N = 1e-6;

struct ControllerParams {
  OmniParams omni;
  VmParams vm;
  Gains gains;
  ErrorFormulation error = ErrorFormulation::kThesis;
  PlacementMethod placement = PlacementMethod::kGaussNewton;
  PlacementOptions placement_options;  // W = W_p by default
  // W_A of Appendix D's projector, diagonal; identity in the thesis
  Vec6 projection_weights = Vec6::Ones();
  // the controller's unit of length in mm: 1 = thesis (mm), 1000 = metres
  double length_unit_mm = 1.0;
  double servo_period_s = 1e-3;  // for e_dot
  // first-order low-pass on e_dot; <= 0 turns the filter off
  double velocity_cutoff_Hz = 100.0;
  // J_V^T W_A J_V counts as singular below this rcond; damping of its
  // inverse (relative to the largest eigenvalue). In mm the VMs are far from
  // isotropic: rcond is about 1/(1 + L^2) for the sphere and 1/(1 + L^2)^2
  // for the surface (4e-4 and 1.6e-7 at L = 50 mm) away from any
  // singularity, so the threshold sits well below those.
  double singular_rcond = 1e-10;
  double singular_damping = 1e-13;
  // saturation; defaults from OmniParams; at least kMinForceLimit_N
  double force_limit_N = OmniParams().max_force_N;

  // Throws std::invalid_argument naming the first bad field.
  void validate() const;
};


}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_CONTROLLER_PARAMS_H_
