// The cases by name, and where their scenes are: the one place that turns
// "case1" into a scene file, for `run`, `hw run`, `view`, the studies and
// the emulator alike. Cases 1-6 are the thesis's six; case 7 is this
// project's line slider (the circle's limit, docs/testbed.md).
#ifndef VMHAPTICS_SIM_CASES_CASE_CATALOGUE_H_
#define VMHAPTICS_SIM_CASES_CASE_CATALOGUE_H_

#include <string>
#include <vector>

namespace vmh::sim {

// The cases, in order: name and scene file under the models directory.
// Adding a case is one line here and one file in models/cases/.
struct CaseEntry {
  const char* name;
  const char* scene;
};
const std::vector<CaseEntry>& case_catalogue();

// The models directory: $VMH_MODELS_DIR if set, else the source tree's.
std::string models_dir();

// A case name ("case1") to its scene path, or a path to itself. Throws
// SimError for a name that is neither a known case nor an existing regular
// file.
std::string resolve_scene(const std::string& case_or_path, std::string* name);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CASES_CASE_CATALOGUE_H_
