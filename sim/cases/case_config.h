// A case's parameters read from a scene: the MJCF <custom> fields (the
// mujoco_mpc habit) with `--set name=value` overrides on top, read once into
// the typed CaseParams of sim/cases/case_params.h, whose table (case_fields())
// lists every parameter with its size, default, unit, range and meaning.
//
// A scene that carries a <custom> field not in the table, or a known field
// under the other kind's tag (a number as <text>, a word as <numeric>), a
// `--set` of an unknown name, a value of the wrong size or out of range, or
// a missing required field is a SimError that names the file (or `--set`)
// and the field.
#ifndef VMHAPTICS_SIM_CASES_CASE_CONFIG_H_
#define VMHAPTICS_SIM_CASES_CASE_CONFIG_H_

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "sim/cases/case_params.h"

namespace vmh::sim {

// CaseParams as read from a scene file.
struct CaseConfig : CaseParams {
  // Reads the fields of `m` (whose file is `source`, for messages) and then
  // applies `overrides`, each "name=value" (vectors comma-separated). Throws
  // SimError on anything the file comment lists.
  static CaseConfig from_model(const mjModel* m, const std::string& source,
                               const std::vector<std::string>& overrides);
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CASES_CASE_CONFIG_H_
