// The `run` verb: the thesis's cases (or any scene) in closed loop, headless.
#ifndef VMHAPTICS_CLI_RUN_H_
#define VMHAPTICS_CLI_RUN_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

// Adds `run` to the application.
void register_run(CLI::App* app);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_RUN_H_
