// The `params` verb: the table of a case's parameters (sim/cases/case_params.h).
#ifndef VMHAPTICS_CLI_PARAMS_H_
#define VMHAPTICS_CLI_PARAMS_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

// Adds `params` to the application.
void register_params(CLI::App* app);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_PARAMS_H_
