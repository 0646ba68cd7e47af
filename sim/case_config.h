// A case's parameters: read from the scene's MJCF <custom> fields with
// defaults (the mujoco_mpc habit), overridden by `--set name=value`, and
// validated at setup time.
//
// Every parameter the simulator knows is listed once, in case_fields(), with
// its size, default, unit and meaning; docs/cli.md prints the same table. A
// scene that carries a <custom> field not in the list, a `--set` of an
// unknown name, a value of the wrong size, or a missing required field is an
// error that names the file and the field.
#ifndef VMHAPTICS_SIM_CASE_CONFIG_H_
#define VMHAPTICS_SIM_CASE_CONFIG_H_

#include <mujoco/mujoco.h>

#include <map>
#include <string>
#include <vector>

#include "controller/controller.h"
#include "controller/types.h"

namespace vmh::sim {

struct FieldSpec {
  const char* name;
  bool is_text;
  int size;               // number of values (numeric fields)
  const char* default_value;  // nullptr: required
  const char* unit;
  const char* doc;
};

// The table of every known field.
const std::vector<FieldSpec>& case_fields();

// Where a value came from.
enum class ValueSource { kDefault, kScene, kOverride };
const char* value_source_name(ValueSource s);  // default, scene, set

class CaseConfig {
 public:
  // Reads the fields of `m` (whose file is `source`, for messages) and then
  // applies `overrides`, each "name=value" (vectors comma-separated). Throws
  // SimError on anything the class comment lists.
  static CaseConfig from_model(const mjModel* m, const std::string& source,
                               const std::vector<std::string>& overrides);

  double number(const std::string& name) const;
  std::vector<double> numbers(const std::string& name) const;
  Vec3 vec3(const std::string& name) const;
  const std::string& text(const std::string& name) const;
  ValueSource source_of(const std::string& name) const;
  const std::string& scene_path() const { return scene_path_; }

 private:
  std::string scene_path_;
  std::map<std::string, std::vector<double>> numbers_;
  std::map<std::string, std::string> texts_;
  std::map<std::string, ValueSource> sources_;
};

// The controller's parameters for this case (VM, gains, formulation,
// placement weights, servo period). Device frame, mm, as the thesis.
ControllerParams controller_params(const CaseConfig& c);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CASE_CONFIG_H_
