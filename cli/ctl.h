// The `ctl` verb of the command line: one or more controller ticks at a
// given joint configuration, as one JSON object.
#ifndef VMHAPTICS_CLI_CTL_H_
#define VMHAPTICS_CLI_CTL_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

// Adds `ctl` to the application.
void register_ctl(CLI::App* app);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_CTL_H_
