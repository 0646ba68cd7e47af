// Helpers shared by the study sub-verbs this file's author wrote (precision,
// leanness): which scene --case names, and writing an output under --out.
#ifndef VMHAPTICS_CLI_STUDY_FILES_H_
#define VMHAPTICS_CLI_STUDY_FILES_H_

#include <string>
#include <vector>

namespace vmh::cli {

// "--case" as given: 1..6, case1..case6 or a scene path. Returns the scene
// path and sets *name; throws UsageError naming `option` otherwise.
std::string study_scene(const std::string& option, const std::string& value,
                        std::string* name);

// Splits "a,b,c" into finite numbers (any count >= 1); UsageError naming
// `option` on an empty item or one that is not a number.
std::vector<double> parse_number_list(const std::string& option,
                                      const std::string& text);

// Creates `dir` if needed and writes dir/name through a temporary file and a
// rename, so that a failed write leaves nothing half-written. Returns the
// path written. Throws std::runtime_error naming the path.
std::string write_study_file(const std::string& dir, const std::string& name,
                             const std::string& text);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_STUDY_FILES_H_
