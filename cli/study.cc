#include "cli/study.h"

namespace vmh::cli {

void register_study(CLI::App* app) {
  CLI::App* study = app->add_subcommand(
      "study", "numerical studies: precision, stability, extremes, leanness, "
      "sensitivity");
  study->require_subcommand(1);
  // sub-verbs (cli/study_<name>.cc) register here as they land
  register_study_extremes(study);
  register_study_precision(study);
  register_study_leanness(study);
  register_study_stability(study);
  register_study_sensitivity(study);
}

}  // namespace vmh::cli
