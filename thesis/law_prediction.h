// What the virtual-mechanism law gives at a pose, computed by a route
// independent of the controller: from the ground-truth wrist centre and
// stylus axis (not the quantised readings), the mechanism's closed-form
// placement and its VM Jacobian built without its joint angles (its
// prediction hook, controller/vm_registry.h: the circle and the sphere,
// §3.3.1, §3.4.1, and the line).
//
// The circle's and the sphere's VM are a link of length L turning about
// the pivot, so whatever their angles, J_V's columns span the rigid
// rotations about the pivot: [w x L u; w] for w along the circle's normal
// n (one column) or any w (the sphere, three columns), u the link axis;
// the line's one column is [t; 0]. Eq. 3.11 projects g = (K_p e_p, K_o e_o) with the held hand's e_dot = 0,
// f = g - W J (J^T W J)^-1 J^T g with W the projection weights, in the
// controller's length unit (docs/controller.md); the force on the wrist is
// f's first three rows (eq. 3.12 with J_v).
//
// Used by thesis/claims.cc to give each claim its `prediction`.
#ifndef VMHAPTICS_THESIS_LAW_PREDICTION_H_
#define VMHAPTICS_THESIS_LAW_PREDICTION_H_

#include <string>

#include "controller/controller.h"

namespace vmh::thesis {

struct LawPrediction {
  bool available = false;
  std::string reason;  // why not, when !available
  Vec3 x_v_mm = Vec3::Zero();  // nearest point of the path, device frame
  Vec3 x_r_mm = Vec3::Zero();  // the VM aligned with the stylus
  Vec3 e_ornt_rad = Vec3::Zero();
  // the law's force on the wrist centre, device frame, before any limit
  Vec3 force_N = Vec3::Zero();
  // the same after the force limit and the motors' torque limits at the
  // pose (one scale for all motors, as the controller and the device do)
  Vec3 force_limited_N = Vec3::Zero();
  bool limited = false;
};

// p_mm and axis: wrist centre (mm) and stylus axis (unit), device frame;
// q_dh: the joint angles (DH, rad) of the same pose, for the torque limits.
// Where the mechanism has a hook (the surface has none), else available =
// false with the reason.
LawPrediction predict_static_law(const ControllerParams& p, const Vec3& p_mm,
                                 const Vec3& axis, const Joints& q_dh);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_LAW_PREDICTION_H_
