// The `compare` verb: device recordings against the project's kinematics
// and the MJCF Omni (docs/bringup.md).
#ifndef VMHAPTICS_CLI_COMPARE_H_
#define VMHAPTICS_CLI_COMPARE_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

void register_compare(CLI::App* app);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_COMPARE_H_
