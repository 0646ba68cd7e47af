#include "viz/overlay.h"

#include <cmath>

#include "controller/device_frame.h"

namespace vmh::viz {
namespace {

constexpr std::array<float, 4> kPathRgba{0.45f, 0.65f, 0.95f, 0.9f};
constexpr std::array<float, 4> kVRgba{0.90f, 0.15f, 0.15f, 1.0f};
constexpr std::array<float, 4> kRRgba{0.15f, 0.75f, 0.20f, 1.0f};
constexpr std::array<float, 4> kStylusRgba{0.95f, 0.85f, 0.10f, 1.0f};
constexpr std::array<float, 4> kForceRgba{0.85f, 0.10f, 0.85f, 1.0f};
constexpr std::array<float, 4> kHandRgba{0.96f, 0.72f, 0.58f, 0.45f};
constexpr std::array<float, 4> kSpringRgba{0.62f, 0.36f, 0.12f, 1.0f};

// a point in the controller's length unit, device frame -> world m
struct ToWorld {
  const OmniParams& omni;
  double unit_mm;
  Vec3 point(const Vec3& p_lu) const {
    return device_mm_to_base(omni, p_lu * unit_mm);
  }
  Vec3 point_mm(const Vec3& p_mm) const {
    return device_mm_to_base(omni, p_mm);
  }
};

OverlayPrimitive segment(OverlayId id, const Vec3& a, const Vec3& b,
                         double r, const std::array<float, 4>& rgba) {
  OverlayPrimitive p;
  p.shape = OverlayPrimitive::Shape::kSegment;
  p.id = id;
  p.a_m = a;
  p.b_m = b;
  p.radius_m = r;
  p.rgba = rgba;
  return p;
}

// a circle of radius r (length unit) about `centre` in the plane spanned by
// the unit vectors u, v (device frame), as n segments in world metres
void add_circle(const ToWorld& w, const Vec3& centre, const Vec3& u,
                const Vec3& v, double r, const OverlayOptions& opt,
                std::vector<OverlayPrimitive>* prims) {
  const int n = opt.circle_segments < 8 ? 8 : opt.circle_segments;
  Vec3 prev = w.point(centre + r * u);
  for (int i = 1; i <= n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    const Vec3 next =
        w.point(centre + r * (std::cos(a) * u + std::sin(a) * v));
    prims->push_back(
        segment(OverlayId::kPath, prev, next, opt.line_radius_m, kPathRgba));
    prev = next;
  }
}

// the path as the mechanism's drawing hook gives it: circles as n
// segments, a sphere as its three great circles in the pivot frame's
// planes, a line as a segment of the surface grid's half width each side of
// X(theta_V)'s foot, a plane as a square grid centred under X(theta_V)
void add_path(const VirtualMechanism& vm, const ToWorld& w,
              const ControlOutput& out, const OverlayOptions& opt,
              std::vector<OverlayPrimitive>* prims) {
  const Vec3 xv_lu = out.x_v_mm / w.unit_mm;
  const double h = opt.surface_half_width_m * 1000.0 / w.unit_mm;
  for (const PathPrimitive& prim : vm.path_primitives()) {
    const Vec3 x = prim.u, y = prim.v, z = prim.u.cross(prim.v);
    switch (prim.type) {
      case PathPrimitive::Type::kCircle:
        add_circle(w, prim.centre, x, y, prim.radius, opt, prims);
        break;
      case PathPrimitive::Type::kSphere:
        add_circle(w, prim.centre, x, y, prim.radius, opt, prims);
        add_circle(w, prim.centre, x, z, prim.radius, opt, prims);
        add_circle(w, prim.centre, y, z, prim.radius, opt, prims);
        break;
      case PathPrimitive::Type::kLine: {
        const Vec3 c = prim.centre + x.dot(xv_lu - prim.centre) * x;
        prims->push_back(segment(OverlayId::kPath, w.point(c - h * x),
                                 w.point(c + h * x), opt.line_radius_m,
                                 kPathRgba));
        break;
      }
      case PathPrimitive::Type::kPlane: {
        // the plane the tip slides on, centred under X(theta_V)
        const Vec3 c = xv_lu - z.dot(xv_lu - prim.centre) * z;
        const int n = opt.surface_lines < 2 ? 2 : opt.surface_lines;
        for (int i = 0; i < n; ++i) {
          const double s = -h + 2.0 * h * i / (n - 1);
          prims->push_back(segment(OverlayId::kPath,
                                   w.point(c + s * x - h * y),
                                   w.point(c + s * x + h * y),
                                   opt.line_radius_m, kPathRgba));
          prims->push_back(segment(OverlayId::kPath,
                                   w.point(c - h * x + s * y),
                                   w.point(c + h * x + s * y),
                                   opt.line_radius_m, kPathRgba));
        }
        break;
      }
    }
  }
}

// the link of the VM at theta: from its pivot (the surface: its tip) to the
// handle, which is L back along the link's axis
void add_link(const VirtualMechanism& vm, const ToWorld& w,
              const VmAngles& theta, OverlayId link, OverlayId point,
              const std::array<float, 4>& rgba, const OverlayOptions& opt,
              std::vector<OverlayPrimitive>* prims) {
  if (theta.size() != vm.dof() || !theta.allFinite()) return;
  const VmPose pose = vm.pose(theta);
  const Vec3 handle = w.point(pose.p);
  const Vec3 root = w.point(pose.p - vm.length() * pose.axis);
  prims->push_back(segment(link, root, handle, 2.0 * opt.line_radius_m,
                           rgba));
  OverlayPrimitive s;
  s.shape = OverlayPrimitive::Shape::kSphere;
  s.id = point;
  s.a_m = s.b_m = handle;
  s.radius_m = opt.point_radius_m;
  s.rgba = rgba;
  prims->push_back(s);
}

}  // namespace

const char* overlay_name(OverlayId id) {
  switch (id) {
    case OverlayId::kPath: return "path";
    case OverlayId::kLinkV: return "link_v";
    case OverlayId::kLinkR: return "link_r";
    case OverlayId::kPointV: return "x_v";
    case OverlayId::kPointR: return "x_r";
    case OverlayId::kStylus: return "stylus";
    case OverlayId::kForce: return "force";
    case OverlayId::kHandTarget: return "hand_target";
    case OverlayId::kHandSpring: return "hand_spring";
  }
  return "?";
}

void overlay_primitives(const VirtualMechanism& vm,
                        const ControllerParams& params,
                        const ControlOutput& out, const OverlayOptions& opt,
                        std::vector<OverlayPrimitive>* prims) {
  prims->clear();
  const ToWorld w{params.omni, params.length_unit_mm};
  if (opt.path) add_path(vm, w, out, opt, prims);
  if (opt.mechanism) {
    add_link(vm, w, out.theta_v, OverlayId::kLinkV, OverlayId::kPointV, kVRgba,
             opt, prims);
    add_link(vm, w, out.theta_r, OverlayId::kLinkR, OverlayId::kPointR, kRRgba,
             opt, prims);
  }
  const Vec3 p = w.point_mm(out.p_rm_mm);
  if (opt.stylus && out.axis_rm.allFinite() && p.allFinite()) {
    const Vec3 a = device_to_base_vector(out.axis_rm).normalized();
    const double h = 0.5 * opt.stylus_length_m;
    prims->push_back(segment(OverlayId::kStylus, p - h * a, p + h * a,
                             1.5 * opt.line_radius_m, kStylusRgba));
  }
  const double f = out.force_device_N.norm();
  if (opt.force && std::isfinite(f) && f >= opt.min_force_N && p.allFinite()) {
    const Vec3 dir = device_to_base_vector(out.force_device_N) / f;
    OverlayPrimitive arrow =
        segment(OverlayId::kForce, p, p + opt.force_m_per_N * f * dir,
                2.5 * opt.line_radius_m, kForceRgba);
    arrow.shape = OverlayPrimitive::Shape::kArrow;
    prims->push_back(arrow);
  }
}

void hand_primitives(const Vec3& target_m, const Mat3& target_R,
                     const Vec3& grip_m, std::vector<OverlayPrimitive>* prims) {
  if (!target_m.allFinite() || !target_R.allFinite() || !grip_m.allFinite()) {
    return;
  }
  // a thumb's and an index finger's pads, 11 mm either side of the pen axis
  // the target asks for, each 24 mm along it: a pen grip, seen through
  const Vec3 along = target_R.col(2).normalized();
  const Vec3 side = target_R.col(0).normalized();
  for (double s : {-1.0, 1.0}) {
    const Vec3 c = target_m + s * 0.011 * side;
    prims->push_back(segment(OverlayId::kHandTarget, c - 0.012 * along,
                             c + 0.012 * along, 0.0065, kHandRgba));
  }
  // the spring from the target to the grip: eight coils of a zig-zag
  // 3 mm to either side of the line
  const Vec3 d = grip_m - target_m;
  const double len = d.norm();
  if (len < 5e-4) return;
  const Vec3 u = d / len;
  Vec3 n = u.cross(side);
  if (n.norm() < 1e-6) n = u.cross(Vec3::UnitZ());
  if (n.norm() < 1e-6) n = u.cross(Vec3::UnitX());
  n.normalize();
  constexpr int kPoints = 17;
  Vec3 prev = target_m;
  for (int i = 1; i <= kPoints; ++i) {
    const double f = static_cast<double>(i) / (kPoints + 1);
    const Vec3 next = target_m + f * d + (i % 2 == 0 ? 1.0 : -1.0) * 0.003 * n;
    prims->push_back(
        segment(OverlayId::kHandSpring, prev, next, 0.0006, kSpringRgba));
    prev = next;
  }
  prims->push_back(
      segment(OverlayId::kHandSpring, prev, grip_m, 0.0006, kSpringRgba));
}

int add_overlay_to_scene(const std::vector<OverlayPrimitive>& prims,
                         mjvScene* scn, float model_alpha) {
  if (!prims.empty() && model_alpha < 1.0f) {
    const float a = model_alpha < 0.0f ? 0.0f : model_alpha;
    for (int i = 0; i < scn->ngeom; ++i) {
      mjvGeom* g = scn->geoms + i;
      if (g->category != mjCAT_DYNAMIC) continue;
      if (g->rgba[3] > a) g->rgba[3] = a;
      g->transparent = 1;
    }
  }
  int added = 0;
  for (const OverlayPrimitive& p : prims) {
    if (scn->ngeom >= scn->maxgeom) break;
    mjvGeom* g = scn->geoms + scn->ngeom;
    const float* rgba = p.rgba.data();
    if (p.shape == OverlayPrimitive::Shape::kSphere) {
      const mjtNum size[3] = {p.radius_m, p.radius_m, p.radius_m};
      const mjtNum pos[3] = {p.a_m.x(), p.a_m.y(), p.a_m.z()};
      mjv_initGeom(g, mjGEOM_SPHERE, size, pos, nullptr, rgba);
    } else {
      // MuJoCo cannot orient a connector of zero length
      if ((p.b_m - p.a_m).norm() < 1e-9) continue;
      mjv_initGeom(g, mjGEOM_NONE, nullptr, nullptr, nullptr, rgba);
      const int type = p.shape == OverlayPrimitive::Shape::kArrow
                           ? mjGEOM_ARROW
                           : mjGEOM_CAPSULE;
      mjv_makeConnector(g, type, p.radius_m, p.a_m.x(), p.a_m.y(), p.a_m.z(),
                        p.b_m.x(), p.b_m.y(), p.b_m.z());
    }
    g->category = mjCAT_DECOR;
    g->transparent = rgba[3] < 1.0f ? 1 : 0;
    g->objtype = mjOBJ_UNKNOWN;
    g->objid = -1;
    scn->ngeom++;
    ++added;
  }
  return added;
}

}  // namespace vmh::viz
