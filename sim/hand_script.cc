#include "sim/hand_script.h"

#include <algorithm>
#include <cmath>

#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;

Vec3 rotate(const Vec3& v, const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()) * v;
}

// smooth 0 -> 1 with zero slope at both ends
double smoothstep(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * (3.0 - 2.0 * s);
}

}  // namespace

HandScript::HandScript(const CaseParams& c, const VmParams& vm)
    : script_(c.script.kind) {
  pivot_ = vm.pivot_mm;
  n_unit_ = vm.R_pivot.col(2).normalized();
  length_mm_ = vm.length_mm;
  off_mm_ = c.script.off_mm;
  misalign_rad_ = c.script.misalign_rad;
  sweep_mm_ = c.script.sweep_mm;
  sweep_rad_ = c.script.sweep_rad;
  const Vec3 dir = c.script.dir.normalized();
  const double D = c.sim.duration_s;

  // the start pose on the path toward `dir`, as the mechanism gives it
  // (controller/virtual_mechanism.h, path_start): for the circle and the
  // line only dir's part in their plane counts, the surface stands its
  // probe upright over its origin
  VmMount mount;
  mount.origin = pivot_;
  mount.R = vm.R_pivot;
  vm_ = make_vm(vm.kind, mount, length_mm_);
  if (!vm_->path_start(dir, &start_)) {
    throw SimError(c.scene_path() + ": field 'script_dir' is along the " +
                   vm_kind_name(vm.kind) +
                   "'s normal; the start pose on the path is undefined");
  }
  axis0_ = start_.axis;
  // an explicit stylus axis, for poses the direction alone cannot give (the
  // stylus along the forearm, or turned away from the link)
  const Vec3 axis_set = c.script.axis;
  if (axis_set.norm() > 1e-9) axis0_ = axis_set.normalized();

  if (script_ == ScriptKind::kHold) {
    segments_ = {{"hold", 0.0, D, true}};
    prepare();
    return;
  }
  if (script_ == ScriptKind::kPivot) {
    // RM at the pivot, where theta_V is undefined (LL = 0 in §3.4.1), then
    // through it: two passes along r0 from one side of the path to the other
    segments_ = {{"at_pivot", 0.0, 0.4 * D, true},
                 {"through_pivot", 0.4 * D, D, false}};
    blend_s_ = std::min(0.3, 0.05 * D);
    prepare();
    return;
  }
  if (script_ == ScriptKind::kSpin) {
    // the point held, the stylus swung about the VM's normal
    segments_ = {{"settle", 0.0, 0.1 * D, true}, {"spin", 0.1 * D, D, false}};
    blend_s_ = std::min(0.3, 0.025 * D);
    prepare();
    return;
  }
  // the thesis script, in twentieths of the run (20 s by default)
  const double u = D / 20.0;
  segments_ = {
      {"settle", 0.0, 1 * u, true},
      {"off_out", 1 * u, 3 * u, true},
      {"off_out_misaligned", 3 * u, 5 * u, true},
      {"off_in", 5 * u, 7 * u, true},
      {"on_misaligned_a", 7 * u, 10 * u, true},
      {"on_misaligned_b", 10 * u, 13 * u, true},
      {"sweep", 13 * u, 20 * u, false},
  };
  blend_s_ = std::min(0.3, 0.25 * u);
  prepare();
}

HandScript::Shape HandScript::shape_of(const std::string& name) {
  if (name == "at_pivot") return Shape::kAtPivot;
  if (name == "through_pivot") return Shape::kThroughPivot;
  if (name == "spin") return Shape::kSpin;
  if (name == "off_out") return Shape::kOffOut;
  if (name == "off_out_misaligned") return Shape::kOffOutMisaligned;
  if (name == "off_in") return Shape::kOffIn;
  if (name == "on_misaligned_a") return Shape::kOnMisalignedA;
  if (name == "on_misaligned_b") return Shape::kOnMisalignedB;
  if (name == "sweep") return Shape::kSweep;
  return Shape::kStart;  // hold, settle: the start pose
}

void HandScript::prepare() {
  const std::size_t n = segments_.size();
  shapes_.resize(n);
  moving_.resize(n);
  held_pose_.assign(n, ScriptPose{});
  blend_from_.assign(n, ScriptPose{});
  for (std::size_t i = 0; i < n; ++i) {
    shapes_[i] = shape_of(segments_[i].name);
    moving_[i] = shapes_[i] == Shape::kThroughPivot ||
                 shapes_[i] == Shape::kSpin || shapes_[i] == Shape::kSweep;
  }
  // the same raw() that a moving segment runs at every call, so a held pose
  // is bit for bit what it would be if worked out at each tick
  for (std::size_t i = 0; i < n; ++i) {
    const int k = static_cast<int>(i);
    if (!moving_[i]) held_pose_[i] = raw(k, segments_[i].t0_s);
    if (i > 0) blend_from_[i] = raw(k - 1, segments_[i].t0_s);
  }
}

int HandScript::segment_at(double t_s) const {
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    if (t_s < segments_[i].t1_s) return static_cast<int>(i);
  }
  return static_cast<int>(segments_.size()) - 1;
}

ScriptPose HandScript::raw(int segment, double t_s) const {
  ScriptPose pose;
  pose.p_mm = start_.p;
  pose.axis = axis0_;
  const Shape shape = shapes_[static_cast<std::size_t>(segment)];
  // misalignment turns the stylus toward the tangent: for the circle and
  // the line about their normal (the circle's theta_R moves along the
  // path); the second on-path hold tilts it about the mechanism's tilt_b
  // (the planar ones: the other way about the normal; the sphere: about
  // the tangent, its polar angle)
  const Vec3 m = start_.outward.cross(start_.tangent);
  // the pivot and spin scripts: two full swings over the segment, starting
  // where the previous segment ended
  auto two_swings = [&]() {
    const ScriptSegment& seg = segments_[static_cast<std::size_t>(segment)];
    const double u = std::max(0.0, t_s - seg.t0_s) / (seg.t1_s - seg.t0_s);
    return std::sin(2.0 * kTwoPi * u);
  };
  switch (shape) {
    case Shape::kStart:
      break;
    case Shape::kAtPivot:
      pose.p_mm = pivot_;
      break;
    case Shape::kThroughPivot:
      pose.p_mm = pivot_ + length_mm_ * two_swings() * start_.outward;
      break;
    case Shape::kSpin:
      pose.axis = Eigen::AngleAxisd(misalign_rad_ * two_swings(), n_unit_) *
                  axis0_;
      break;
    case Shape::kOffOut:
      pose.p_mm = start_.p + off_mm_ * start_.outward;
      break;
    case Shape::kOffOutMisaligned:
      pose.p_mm = start_.p + off_mm_ * start_.outward;
      pose.axis = rotate(axis0_, m, misalign_rad_);
      break;
    case Shape::kOffIn:
      pose.p_mm = start_.p - off_mm_ * start_.outward;
      break;
    case Shape::kOnMisalignedA:
      pose.axis = rotate(axis0_, m, misalign_rad_);
      break;
    case Shape::kOnMisalignedB:
      pose.axis = rotate(axis0_, start_.tilt_b, misalign_rad_);
      break;
    case Shape::kSweep: {
      const ScriptSegment& s = segments_[static_cast<std::size_t>(segment)];
      const double T = s.t1_s - s.t0_s;
      const double tau = std::max(0.0, t_s - s.t0_s);
      // one slow pass along the path, four across it, both starting at the
      // start pose
      const double phi = sweep_rad_ * std::sin(kTwoPi * tau / T);
      const double across = sweep_mm_ * std::sin(4.0 * kTwoPi * tau / T);
      // along the path as the mechanism moves (turning about its normal,
      // or sliding), the stylus turned with it
      Mat3 turn;
      vm_->along_path(start_, phi, across, &pose.p_mm, &turn);
      pose.axis = turn * axis0_;
      break;
    }
  }
  return pose;
}

// raw(), from the poses prepare() kept where they do not move
ScriptPose HandScript::evaluate(int segment, double t_s) const {
  const auto i = static_cast<std::size_t>(segment);
  return moving_[i] ? raw(segment, t_s) : held_pose_[i];
}

ScriptPose HandScript::at(double t_s) const {
  const int k = segment_at(t_s);
  ScriptPose pose = evaluate(k, t_s);
  const ScriptSegment& s = segments_[static_cast<std::size_t>(k)];
  if (k > 0 && t_s - s.t0_s < blend_s_) {
    // blend in from where the previous segment ended
    const ScriptPose& from = blend_from_[static_cast<std::size_t>(k)];
    const double w = smoothstep((t_s - s.t0_s) / blend_s_);
    pose.p_mm = (1.0 - w) * from.p_mm + w * pose.p_mm;
    const Eigen::Quaterniond q =
        Eigen::Quaterniond::Identity().slerp(
            w, Eigen::Quaterniond::FromTwoVectors(from.axis, pose.axis));
    pose.axis = (q * from.axis).normalized();
  }
  return pose;
}

}  // namespace vmh::sim
