// viz/overlay: the overlay's geometry checked against the controller's own
// closed forms and frame conversions, computed by other routes than the
// overlay's (the VM's distance_to_path, the controller's force_base_N), and
// its mjvGeoms against MuJoCo's connector convention. No window.
#include "viz/overlay.h"

#include <gtest/gtest.h>

#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh::viz {
namespace {

ControllerParams params_for(VmKind kind) {
  ControllerParams p;
  p.vm.kind = kind;
  p.vm.length_mm = 50.0;
  p.gains.k_pos_N_per_mm = 0.5;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  return p;
}

// a pose 7 mm off the 50 mm path with a misaligned stylus (scripts/demo's)
const Joints kQ = (Joints() << 0.2927, 0.1303, -0.0303, 0.3, -0.4, 0.2)
                      .finished();

struct Ticked {
  ControllerParams params;
  Controller controller;
  ControlOutput out;
  explicit Ticked(VmKind kind)
      : params(params_for(kind)), controller(params) {
    controller.tick(kQ, &out);
  }
};

std::vector<OverlayPrimitive> of_id(const std::vector<OverlayPrimitive>& all,
                                    OverlayId id) {
  std::vector<OverlayPrimitive> r;
  for (const auto& p : all) {
    if (p.id == id) r.push_back(p);
  }
  return r;
}

TEST(Overlay, CirclePathLiesOnTheCircleInItsPlane) {
  Ticked t(VmKind::kCircle);
  ASSERT_FALSE(is_fault(t.out.status));
  std::vector<OverlayPrimitive> prims;
  overlay_primitives(t.controller.mechanism(), t.params, t.out, {}, &prims);
  const auto path = of_id(prims, OverlayId::kPath);
  ASSERT_EQ(path.size(), 96u);
  for (const auto& s : path) {
    for (const Vec3& end_m : {s.a_m, s.b_m}) {
      const Vec3 p_mm = base_to_device_mm(t.params.omni, end_m);
      EXPECT_NEAR(t.controller.mechanism().distance_to_path(p_mm), 0.0, 1e-9);
      EXPECT_NEAR(p_mm.z(), 0.0, 1e-9);  // device x-y plane (Appendix D)
    }
  }
  // closed: the last segment ends where the first begins
  EXPECT_LT((path.back().b_m - path.front().a_m).norm(), 1e-12);
}

TEST(Overlay, SpherePathIsThreeGreatCircles) {
  Ticked t(VmKind::kSphere);
  std::vector<OverlayPrimitive> prims;
  OverlayOptions opt;
  opt.circle_segments = 40;
  overlay_primitives(t.controller.mechanism(), t.params, t.out, opt, &prims);
  const auto path = of_id(prims, OverlayId::kPath);
  ASSERT_EQ(path.size(), 120u);
  for (const auto& s : path) {
    const Vec3 p_mm = base_to_device_mm(t.params.omni, s.a_m);
    EXPECT_NEAR(p_mm.norm(), 50.0, 1e-9);
  }
}

TEST(Overlay, LinksEndAtTheControllersHandlePositions) {
  for (VmKind kind : {VmKind::kCircle, VmKind::kSphere, VmKind::kSurface,
                      VmKind::kLine}) {
    Ticked t(kind);
    std::vector<OverlayPrimitive> prims;
    overlay_primitives(t.controller.mechanism(), t.params, t.out, {}, &prims);
    const auto v = of_id(prims, OverlayId::kPointV);
    const auto r = of_id(prims, OverlayId::kPointR);
    const auto lv = of_id(prims, OverlayId::kLinkV);
    ASSERT_EQ(v.size(), 1u);
    ASSERT_EQ(r.size(), 1u);
    ASSERT_EQ(lv.size(), 1u);
    // the controller's x_v_mm / x_r_mm, converted by the device-frame map
    EXPECT_LT((v[0].a_m - device_mm_to_base(t.params.omni, t.out.x_v_mm))
                  .norm(), 1e-12);
    EXPECT_LT((r[0].a_m - device_mm_to_base(t.params.omni, t.out.x_r_mm))
                  .norm(), 1e-12);
    // the link is L long and ends at the handle
    EXPECT_NEAR((lv[0].b_m - lv[0].a_m).norm(), 0.050, 1e-12);
    EXPECT_LT((lv[0].b_m - v[0].a_m).norm(), 1e-12);
    if (kind == VmKind::kCircle || kind == VmKind::kSphere) {  // from the pivot
      EXPECT_LT((lv[0].a_m - device_mm_to_base(t.params.omni, Vec3::Zero()))
                    .norm(), 1e-12);
    }
  }
}

// The line slider's path: one segment on the line (device y through the
// pivot), centred on the foot of X(theta_V), the grid's half width each way
TEST(Overlay, LineIsASegmentOnTheLine) {
  Ticked t(VmKind::kLine);
  OverlayOptions opt;
  std::vector<OverlayPrimitive> prims;
  overlay_primitives(t.controller.mechanism(), t.params, t.out, opt, &prims);
  const auto path = of_id(prims, OverlayId::kPath);
  ASSERT_EQ(path.size(), 1u);
  const Vec3 a = base_to_device_mm(t.params.omni, path[0].a_m);
  const Vec3 b = base_to_device_mm(t.params.omni, path[0].b_m);
  for (const Vec3& e : {a, b}) {
    EXPECT_NEAR(e.x(), 0.0, 1e-9);
    EXPECT_NEAR(e.z(), 0.0, 1e-9);
  }
  EXPECT_NEAR((b - a).norm(), 2000.0 * opt.surface_half_width_m, 1e-9);
  EXPECT_NEAR(0.5 * (a.y() + b.y()), t.out.x_v_mm.y(), 1e-9);
}

TEST(Overlay, ForceArrowPointsAlongTheBaseFrameForce) {
  Ticked t(VmKind::kCircle);
  ASSERT_GT(t.out.force_device_N.norm(), 0.5);
  OverlayOptions opt;
  opt.force_m_per_N = 0.01;
  std::vector<OverlayPrimitive> prims;
  overlay_primitives(t.controller.mechanism(), t.params, t.out, opt, &prims);
  const auto f = of_id(prims, OverlayId::kForce);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].shape, OverlayPrimitive::Shape::kArrow);
  // starts at the wrist centre: forward kinematics of q, DH base frame
  const Vec3 p_base_m = omni_fk(t.params.omni, kQ).p_base_m;
  EXPECT_LT((f[0].a_m - p_base_m).norm(), 1e-9);
  const Vec3 d = f[0].b_m - f[0].a_m;
  EXPECT_NEAR(d.norm(), 0.01 * t.out.force_base_N.norm(), 1e-12);
  EXPECT_GT(d.normalized().dot(t.out.force_base_N.normalized()),
            1.0 - 1e-12);
}

TEST(Overlay, OptionsLeaveOutWhatIsSwitchedOff) {
  Ticked t(VmKind::kCircle);
  OverlayOptions opt;
  opt.path = false;
  opt.force = false;
  std::vector<OverlayPrimitive> prims;
  overlay_primitives(t.controller.mechanism(), t.params, t.out, opt, &prims);
  EXPECT_TRUE(of_id(prims, OverlayId::kPath).empty());
  EXPECT_TRUE(of_id(prims, OverlayId::kForce).empty());
  EXPECT_EQ(of_id(prims, OverlayId::kStylus).size(), 1u);
  // a zero force draws no arrow even when asked for
  ControlOutput zero = t.out;
  zero.force_device_N.setZero();
  overlay_primitives(t.controller.mechanism(), t.params, zero, {}, &prims);
  EXPECT_TRUE(of_id(prims, OverlayId::kForce).empty());
}

TEST(Overlay, SceneGeomsFollowMujocosConnectorConvention) {
  Ticked t(VmKind::kCircle);
  std::vector<OverlayPrimitive> prims;
  OverlayOptions opt;
  opt.circle_segments = 8;
  overlay_primitives(t.controller.mechanism(), t.params, t.out, opt, &prims);
  mjvScene scn;
  mjv_defaultScene(&scn);
  std::vector<mjvGeom> geoms(64);
  scn.geoms = geoms.data();
  scn.maxgeom = 64;
  scn.ngeom = 0;
  const int n = add_overlay_to_scene(prims, &scn);
  ASSERT_EQ(n, static_cast<int>(prims.size()));
  const auto& arrow_prim = prims.back();
  ASSERT_EQ(arrow_prim.id, OverlayId::kForce);
  const mjvGeom& g = scn.geoms[n - 1];
  EXPECT_EQ(g.type, mjGEOM_ARROW);
  // an arrow's frame: its z axis along the arrow, its length in size[2]
  const Vec3 z(g.mat[2], g.mat[5], g.mat[8]);
  const Vec3 d = arrow_prim.b_m - arrow_prim.a_m;
  EXPECT_GT(z.dot(d.normalized()), 1.0 - 1e-5);
  EXPECT_NEAR(g.size[2], d.norm(), 1e-6);
  // the model's geoms already there are faded, decorations are not
  scn.ngeom = 2;
  mjv_initGeom(&scn.geoms[0], mjGEOM_BOX, nullptr, nullptr, nullptr, nullptr);
  scn.geoms[0].category = mjCAT_DYNAMIC;
  scn.geoms[0].rgba[3] = 1.0f;
  scn.geoms[0].transparent = 0;
  mjv_initGeom(&scn.geoms[1], mjGEOM_BOX, nullptr, nullptr, nullptr, nullptr);
  scn.geoms[1].category = mjCAT_DECOR;
  scn.geoms[1].rgba[3] = 1.0f;
  add_overlay_to_scene(prims, &scn, 0.25f);
  EXPECT_FLOAT_EQ(scn.geoms[0].rgba[3], 0.25f);
  EXPECT_EQ(scn.geoms[0].transparent, 1);
  EXPECT_FLOAT_EQ(scn.geoms[1].rgba[3], 1.0f);
  // with nothing to draw the model is left alone
  scn.ngeom = 1;
  scn.geoms[0].rgba[3] = 1.0f;
  add_overlay_to_scene({}, &scn, 0.25f);
  EXPECT_FLOAT_EQ(scn.geoms[0].rgba[3], 1.0f);
  // a full scene takes no more
  scn.ngeom = 62;
  EXPECT_EQ(add_overlay_to_scene(prims, &scn), 2);
  EXPECT_EQ(scn.ngeom, 64);
}

}  // namespace
}  // namespace vmh::viz

namespace vmh::viz {
namespace {

// The hand: two pads either side of the target's pen axis, 11 mm off it,
// and a spring whose segments run from the target to the grip site without
// a gap (each starts where the last ended), its zig-zag within 3 mm of the
// line. Exact to rounding.
TEST(Overlay, HandIsTwoPadsAndASpringFromTargetToGrip) {
  const Vec3 target(0.1, 0.02, -0.1);
  const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 grip = target + Vec3(0.01, -0.02, 0.005);
  std::vector<OverlayPrimitive> prims;
  hand_primitives(target, R, grip, &prims);
  ASSERT_GT(prims.size(), 4u);
  EXPECT_EQ(prims[0].id, OverlayId::kHandTarget);
  EXPECT_EQ(prims[1].id, OverlayId::kHandTarget);
  for (int i = 0; i < 2; ++i) {
    const Vec3 mid = 0.5 * (prims[i].a_m + prims[i].b_m);
    EXPECT_NEAR((mid - target).norm(), 0.011, 1e-12);
    EXPECT_NEAR(std::abs((prims[i].b_m - prims[i].a_m).normalized().dot(R.col(2))),
                1.0, 1e-12);
    EXPECT_LT(prims[i].rgba[3], 1.0f);  // translucent
  }
  Vec3 at = target;
  const Vec3 u = (grip - target).normalized();
  for (std::size_t i = 2; i < prims.size(); ++i) {
    EXPECT_EQ(prims[i].id, OverlayId::kHandSpring);
    EXPECT_LT((prims[i].a_m - at).norm(), 1e-15);
    const Vec3 off = (prims[i].b_m - target) - u.dot(prims[i].b_m - target) * u;
    EXPECT_LE(off.norm(), 0.003 + 1e-12);
    at = prims[i].b_m;
  }
  EXPECT_LT((at - grip).norm(), 1e-15);
  // no spring when the grip sits on its target
  prims.clear();
  hand_primitives(target, R, target, &prims);
  EXPECT_EQ(prims.size(), 2u);
}

}  // namespace
}  // namespace vmh::viz
