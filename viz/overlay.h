// What the viewer and the renderer draw over the MuJoCo scene: the virtual
// mechanism and the control law's state at one servo tick.
//
// The primitives are computed here from the controller's own output and its
// VirtualMechanism (controller/), with no MuJoCo and no OpenGL, so that
// their geometry is unit-tested without a window (tests/viz/overlay_test.cc).
// add_overlay_to_scene() turns them into mjvGeoms.
//
// Frames and units: every primitive is in the MuJoCo world frame, which is
// the DH base frame of the Omni model (models/omni/README.md), in metres.
// The controller's quantities (device frame, its length unit) are converted
// with controller/device_frame.h.
//
// What is drawn (colours as in the SVG views, studies/plot_svg.h):
//   kPath        the VM's path: the circle (a closed polyline in its plane),
//                the sphere (three great circles of its mount frame), the
//                surface (a square grid on the plane the probe's tip slides
//                on, centred under X(theta_V));
//   kLinkV       the VM's link at theta_V, pivot (or tip) -> X(theta_V), red;
//   kLinkR       the VM's link at theta_R, pivot (or tip) -> X(theta_R), green;
//   kPointV/R    X(theta_V) and X(theta_R) as small spheres;
//   kStylus      the stylus axis through the wrist centre p, yellow;
//   kForce       the commanded force F (after saturation) as an arrow from p,
//                force_m_per_N x |F| long, magenta; left out when |F| is
//                below min_force_N.
#ifndef VMHAPTICS_VIZ_OVERLAY_H_
#define VMHAPTICS_VIZ_OVERLAY_H_

#include <array>
#include <vector>

#include <mujoco/mujoco.h>

#include "controller/controller.h"
#include "controller/virtual_mechanism.h"

namespace vmh::viz {

enum class OverlayId {
  kPath,
  kLinkV,
  kLinkR,
  kPointV,
  kPointR,
  kStylus,
  kForce,
};

// a name for each id ("path", "link_v", ...), for tests and screenshots
const char* overlay_name(OverlayId id);

struct OverlayPrimitive {
  enum class Shape { kSegment, kArrow, kSphere };
  Shape shape = Shape::kSegment;
  OverlayId id = OverlayId::kPath;
  // world (DH base) frame, m: a segment's or an arrow's ends (from a to b);
  // a sphere's centre is a (b == a)
  Vec3 a_m = Vec3::Zero();
  Vec3 b_m = Vec3::Zero();
  double radius_m = 0.0;  // line or arrow-shaft radius, or sphere radius
  std::array<float, 4> rgba{1.0f, 1.0f, 1.0f, 1.0f};
};

struct OverlayOptions {
  bool path = true;       // kPath
  bool mechanism = true;  // kLinkV, kLinkR, kPointV, kPointR
  bool stylus = true;     // kStylus
  bool force = true;      // kForce
  double force_m_per_N = 0.02;   // arrow length per newton
  double min_force_N = 1e-3;     // below this no arrow is drawn
  double stylus_length_m = 0.04;  // the stylus segment, centred on p
  double line_radius_m = 0.0008;
  double point_radius_m = 0.003;
  int circle_segments = 96;       // per circle of the path
  int surface_lines = 9;          // grid lines each way on the surface
  double surface_half_width_m = 0.08;
};

// The primitives for one tick: `vm` and `params` are the controller's
// (Controller::mechanism(), Controller::params()), `out` its output for the
// tick. Appends to *prims (cleared first). Allocates (a viewer's frame, not
// the servo tick).
void overlay_primitives(const VirtualMechanism& vm,
                        const ControllerParams& params,
                        const ControlOutput& out, const OverlayOptions& opt,
                        std::vector<OverlayPrimitive>* prims);

// Adds the primitives to the scene as mjvGeoms (lines and arrows as MuJoCo
// connectors, points as spheres), after what mjv_updateScene put there.
// The model's own geoms already in the scene are first made translucent
// (their alpha times `model_alpha`, in [0, 1]; 1 leaves them alone): the
// links, X(theta_V) and the force arrow mostly run inside the gimbal and
// the stylus, where opaque bodies would hide them. Nothing is faded when
// there are no primitives. Stops when the scene is full; returns how many
// were added.
inline constexpr float kOverlayModelAlpha = 0.35f;
int add_overlay_to_scene(const std::vector<OverlayPrimitive>& prims,
                         mjvScene* scn,
                         float model_alpha = kOverlayModelAlpha);

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_OVERLAY_H_
