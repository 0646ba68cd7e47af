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
// What is drawn (colours as in the SVG views, thesis/plot_svg.h):
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
//                below min_force_N;
//   kHandTarget  the simulated hand's target (the mocap body hand_target,
//                sim/hand.h): two translucent fingertip pads either side of
//                the pen axis the target asks for, skin-coloured;
//   kHandSpring  the hand's coupling, target to the stylus's grip site, as
//                a zig-zag spring line, brown: who pushes the stylus, and
//                where to (hand_primitives(), drawn in every case).
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
  kHandTarget,
  kHandSpring,
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

// The simulated hand: its target pose (world frame, m; R's columns the
// target frame's axes, z along the pen) and the grip site it pulls toward
// it. Appends the kHandTarget pads and, when the two are more than 0.5 mm
// apart, the kHandSpring zig-zag to *prims (not cleared).
void hand_primitives(const Vec3& target_m, const Mat3& target_R,
                     const Vec3& grip_m, std::vector<OverlayPrimitive>* prims);

// Adds the primitives to the scene as mjvGeoms (lines and arrows as MuJoCo
// connectors, points as spheres), after what mjv_updateScene put there; a
// primitive with alpha below 1 is drawn as transparent. The moving bodies
// already in the scene (category mjCAT_DYNAMIC: the device's links, not
// the desk or the base) are first given an alpha of at most `model_alpha`
// (in [0, 1]; 1 leaves them alone): X(theta_V) and the force arrow start
// at the wrist centre, inside the gimbal, and a slightly translucent device
// shows them while it stays plainly solid. Nothing is faded when there are
// no primitives. Stops when the scene is full; returns how many were added.
inline constexpr float kOverlayModelAlpha = 0.8f;
int add_overlay_to_scene(const std::vector<OverlayPrimitive>& prims,
                         mjvScene* scn,
                         float model_alpha = kOverlayModelAlpha);

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_OVERLAY_H_
