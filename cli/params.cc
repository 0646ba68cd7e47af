// `vmhaptics params`: every parameter of a case (the scene's <custom> name,
// which is also the `--set` name, the `ctl` option, type, unit, default,
// range and meaning) as Markdown on stdout, made from the one table in
// sim/cases/case_params.cc. docs/parameters.md is this output, verbatim
// (tests/cli/ctl_test.cc checks it):
//   build/vmhaptics params > docs/parameters.md
#include "cli/params.h"

#include <iostream>

#include "sim/cases/case_params.h"

namespace vmh::cli {

void register_params(CLI::App* app) {
  CLI::App* cmd = app->add_subcommand(
      "params",
      "the table of a case's parameters (<custom> field, --set name, ctl "
      "option, unit, default, range, meaning) as Markdown on stdout; "
      "docs/parameters.md is its output");
  cmd->callback([] { std::cout << sim::parameters_markdown() << std::flush; });
}

}  // namespace vmh::cli
