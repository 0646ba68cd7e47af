#include "cli/study.h"

namespace vmh::cli {
namespace {

// A sub-verb of `study`: its name and the function that registers it.
struct StudyVerb {
  const char* name;
  void (*add)(CLI::App* study, const char* name);
};

// The sub-verbs, in the order `vmhaptics study --help` lists them
// (docs/cli.md).
constexpr StudyVerb kStudyVerbs[] = {
    {"extremes", register_study_extremes},
    {"precision", register_study_precision},
    {"leanness", register_study_leanness},
    {"stability", register_study_stability},
    {"sensitivity", register_study_sensitivity},
    {"merge", register_study_merge},
};

}  // namespace

void register_study(CLI::App* app) {
  CLI::App* study = app->add_subcommand(
      "study", "numerical studies: precision, stability, extremes, leanness, "
      "sensitivity");
  study->require_subcommand(1);
  for (const StudyVerb& v : kStudyVerbs) v.add(study, v.name);
}

}  // namespace vmh::cli
