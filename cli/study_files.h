// Helpers shared by the study sub-verbs (precision, leanness): which scene
// --case names, and lists of numbers.
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

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_STUDY_FILES_H_
