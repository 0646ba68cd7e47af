// Changes to the MJCF Omni after it is compiled: the uncertain parameters
// that identification fits (masses and inertias, joint damping and dry
// friction, motor gains and signs), the geometry a bring-up may find off
// (the link lengths), and the one wiring choice a bring-up may find wrong
// (whether motor 3 turns the forearm's absolute or relative angle).
//
// They act on a loaded mjModel by name (the bodies, joints, tendons and
// motors of models/omni/omni.xml), so they apply to any scene that includes
// that model, whatever else it holds (the hand, a slider). Used by the
// emulator's seeded faults, by compare's alternative hypotheses and by
// identification's fit; `--model FILE` copies a calibrated Omni's values
// into a scene the same way (copy_omni_parameters).
#ifndef VMHAPTICS_SIM_OMNI_MODEL_EDIT_H_
#define VMHAPTICS_SIM_OMNI_MODEL_EDIT_H_

#include <mujoco/mujoco.h>

#include <functional>
#include <string>

#include "controller/types.h"

namespace vmh::sim {

// The Omni's named parts in models/omni/omni.xml
inline constexpr const char* kOmniBodies[6] = {
    "turret", "upper_arm", "forearm", "gimbal_yaw", "gimbal_pitch", "stylus"};
inline constexpr const char* kOmniJoints[6] = {"q1", "q2", "q3",
                                               "q4", "q5", "q6"};
inline constexpr const char* kOmniMotors[3] = {"m1", "m2", "m3"};

// Multiplicative changes from the model as written; the identity by default.
struct OmniModelEdit {
  double mass_scale = 1.0;      // every Omni body's mass and inertia
  double damping_scale = 1.0;   // dof_damping of q1..q6
  double friction_scale = 1.0;  // dof_frictionloss of q1..q6
  // actuator gear of m1..m3 (a negative entry flips that motor's sign)
  Vec3 motor_gain = Vec3::Ones();
  double link1_scale = 1.0;  // l1: the forearm's offset from the shoulder
  double link2_scale = 1.0;  // l2: the wrist centre's offset from the elbow
  // motor 3 turns q3 (the relative elbow angle) instead of t3 = q2 + q3
  bool motor3_relative = false;

  bool is_identity() const;
};

// Applies `edit` to m (a model holding the Omni) and recomputes its
// constants (mj_setConst). Throws SimError naming the missing part when m
// has no Omni, std::invalid_argument naming a non-finite or non-positive
// scale.
void apply_omni_edit(mjModel* m, const OmniModelEdit& edit);

// The edit as text, "mass_scale=2,friction_scale=3" (identity: "none")
std::string omni_edit_text(const OmniModelEdit& edit);

// Copies the Omni's dynamic and geometric parameters, by name, from `src`
// (a calibrated Omni, e.g. models/omni/calibrated/<serial>.xml) into `dst`:
// body masses, inertias, centres of mass and offsets; joint damping,
// friction, armature and ranges; motor gears and ranges; tendon
// coefficients. Then mj_setConst. Throws SimError naming the part missing
// from either model.
void copy_omni_parameters(mjModel* dst, const mjModel* src,
                          const std::string& src_name);

// Loads an Omni model file (standalone MJCF) and copies its parameters
// into dst (copy_omni_parameters). Throws SimError naming the file.
void load_omni_parameters(mjModel* dst, const std::string& omni_xml_path);

// What a scene's loader applies to its model right after loading it
// (ClosedLoop's model hook): empty does nothing
using ModelHook = std::function<void(mjModel*)>;

// A hook applying `--model FILE` (when not empty) and then `edit`
ModelHook omni_model_hook(const std::string& omni_xml_path,
                          const OmniModelEdit& edit = {});

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_OMNI_MODEL_EDIT_H_
