// Hand scripts: where the hand tries to put the stylus, as a function of
// time. They reproduce the thesis's experiments (ch. 4): the RM held off the
// VM's path, held on it with the stylus misaligned, and swept along and
// across it. Two more scripts stress the controller where it is weakest:
// `pivot` puts the RM at the VM's pivot and drives it through (theta_V
// undefined), `spin` swings the stylus about the VM's normal (the thesis
// orientation error can wrap through +-pi).
//
// A script gives a wrist-centre position (device frame, mm) and a stylus
// axis (device frame, unit; the z column of the OpenHaptics stylus
// transform). The hand's spring pulls toward it, so where the RM ends up
// depends on the VM's force too; the claims are measured on where it is, not
// on the target.
#ifndef VMHAPTICS_SIM_HAND_SCRIPT_H_
#define VMHAPTICS_SIM_HAND_SCRIPT_H_

#include <memory>
#include <string>
#include <vector>

#include "controller/controller.h"
#include "device/tick_record.h"
#include "sim/cases/case_config.h"

namespace vmh::sim {

// ScriptPose (a wrist-centre target and a stylus axis, device frame) is
// vmh::ScriptPose, device/tick_record.h: records carry it

// A named stretch of the script. Claims use its settled window (the second
// half of a hold, after the transition), never the transition.
struct ScriptSegment {
  std::string name;
  double t0_s = 0.0;
  double t1_s = 0.0;
  bool hold = true;  // the target stands still (after its blend-in)
  double settled_from_s() const { return t0_s + 0.5 * (t1_s - t0_s); }
};

class HandScript {
 public:
  // Builds the script c.script for the VM of `vm` (pivot, L, plane) over
  // c.sim.duration_s. Throws SimError, naming c's scene, if the script does
  // not apply to the VM.
  HandScript(const CaseParams& c, const VmParams& vm);

  ScriptPose at(double t_s) const;
  // index of the segment holding t (the last one past the end)
  int segment_at(double t_s) const;
  const std::vector<ScriptSegment>& segments() const { return segments_; }
  // how long each segment's target takes to blend in from the previous
  // one's end (s): a hold's target stands still from t0_s + blend_s() on
  double blend_s() const { return blend_s_; }

  // the geometry the script is built on: start point on the path, the
  // outward direction there, the tangent along which misalignment and the
  // sweep move, the normal of the sweep plane (all device frame)
  const Vec3& start_mm() const { return start_.p; }
  const Vec3& outward() const { return start_.outward; }
  const Vec3& tangent() const { return start_.tangent; }

 private:
  // what a segment does with the pose; named by ScriptSegment::name
  enum class Shape {
    kStart, kAtPivot, kThroughPivot, kSpin, kOffOut, kOffOutMisaligned,
    kOffIn, kOnMisalignedA, kOnMisalignedB, kSweep
  };
  static Shape shape_of(const std::string& segment_name);
  // the segments' shapes, and the poses that do not depend on time, worked
  // out once (at() runs every servo tick, twice for the hand's velocity)
  void prepare();
  ScriptPose raw(int segment, double t_s) const;
  ScriptPose evaluate(int segment, double t_s) const;


  ScriptKind script_;
  std::vector<ScriptSegment> segments_;
  // the mechanism in mm, for its path_start and along_path hooks
  std::shared_ptr<const VirtualMechanism> vm_;
  PathStart start_;
  Vec3 pivot_, axis0_;  // axis0_: start_.axis, or the case's script_axis
  Vec3 n_unit_;  // the pivot frame's z, for the spin's rotation
  double length_mm_, off_mm_, misalign_rad_, sweep_mm_, sweep_rad_;
  double blend_s_ = 0.3;
  // per segment: its shape; whether its pose moves with time; its pose
  // when it does not; the pose the previous segment ended at (its blend's
  // start)
  std::vector<Shape> shapes_;
  std::vector<char> moving_;
  std::vector<ScriptPose> held_pose_;
  std::vector<ScriptPose> blend_from_;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_HAND_SCRIPT_H_
