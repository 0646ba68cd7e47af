// The `kin` verb of the command line.
#ifndef VMHAPTICS_CLI_KIN_H_
#define VMHAPTICS_CLI_KIN_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

// Adds `kin fk|jac|ik|params` to the application.
void register_kin(CLI::App* app);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_KIN_H_
