// The `study` verb: the numerical studies (docs/numerics.md). Each study is
// a sub-verb registered by its own file, cli/study_<name>.cc:
//   vmhaptics study precision   error against run time per integrator
//   vmhaptics study stability   K_crit of the sampled-data loop vs theory
//   vmhaptics study extremes    stiff and extreme cases, with named outcomes
//   vmhaptics study leanness    steps/s as composed vs with everything on
//   vmhaptics study sensitivity how far each claim survives the model's
//                               uncertainty (and `study merge` of its shards)
// Each prints one JSON object on stdout and, with --out DIR, writes its
// tables (CSV, units in the column names) and plots (SVG) under DIR.
// The sub-verbs are one table in cli/study.cc (kStudyVerbs): a new study is
// its files in studies/ (studies/README.md, "One shape"), one
// cli/study_<name>.cc defining its register function, declared here, and
// one row of that table.
#ifndef VMHAPTICS_CLI_STUDY_H_
#define VMHAPTICS_CLI_STUDY_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

// Adds `study` and its sub-verbs to the application.
void register_study(CLI::App* app);

// One per sub-verb, each adding itself under `study` as `name` (its row's
// in kStudyVerbs) with its options and its callback.
void register_study_precision(CLI::App* study, const char* name);
void register_study_stability(CLI::App* study, const char* name);
void register_study_extremes(CLI::App* study, const char* name);
void register_study_leanness(CLI::App* study, const char* name);
// sensitivity and the merge of its shards (cli/study_sensitivity.cc)
void register_study_sensitivity(CLI::App* study, const char* name);
void register_study_merge(CLI::App* study, const char* name);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_STUDY_H_
