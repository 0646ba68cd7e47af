// The report's job (`vmhaptics report`, cli/report.cc): runs into a folder
// what the page needs, or with `reuse` takes what is already there, and
// writes the page, DIR/report.html (thesis/report_html.h).
//
// What it runs into DIR: the six thesis cases as `run --all --out DIR`
// writes them (DIR/<case>/), and the extreme scenarios, the stability map
// of a light slider and the precision study on case 1 as the `study`
// verbs write them (DIR/study/). With `quick`, a short precision study
// (1 s of case 1, three steps) and a coarse map (5 B values, h = 20 us);
// the cases and the extreme scenarios in full, so the claims are the
// same. Then per case its force field and the thesis's figures
// (DIR/<case>/force_field.svg, thesis.svg) and, through `render`, one
// picture of the scene.
//
// Signals: the caller holds a StopSignals (device/stop_signal.h); the job
// polls it between the runs' ticks, between the studies, between the
// cases' figures and before the page goes in, and then throws
// runtime::SignalStop named as report's, so that DIR keeps only whole sets
// and files and the previous report.html. A signal while the page goes in
// lets it finish; the SignalStop then says it was written whole.
#ifndef VMHAPTICS_STUDIES_REPORT_JOB_H_
#define VMHAPTICS_STUDIES_REPORT_JOB_H_

#include <string>
#include <vector>

#include "thesis/report_html.h"

namespace vmh::studies {

struct ReportJob {
  std::string out_dir = "out/report";
  bool reuse = false;  // take the files already in out_dir
  int jobs = 1;        // runs in parallel, >= 1
  bool quick = false;
  // the page's header: what made it
  std::string command_line, version, git_describe, generated_utc;
  // one picture per case, or why there is none (must be set)
  thesis::RenderFn render;
};

struct ReportOutcome {
  std::string page;                // the page's path
  std::vector<std::string> cases;  // in the page's order
  std::vector<std::string> reused, ran;  // cases' and studies' names
  thesis::ClaimTally tally;
  double wall_s = 0.0;  // the job, first to last
};

// Makes the job's folders (out_dir and out_dir/study). Throws
// std::invalid_argument "cannot create directory '<out_dir>/study'" when
// they cannot be made or are not folders. make_report() calls it first; a
// caller that refuses such a folder as bad input before anything else
// (the command line: exit 2) calls it itself.
void make_report_folders(const ReportJob& job);

// Runs the job. Throws std::invalid_argument for jobs < 1, an empty
// out_dir, no render or a folder that cannot be made (naming it);
// std::runtime_error naming the case or file for a run that failed or a
// study's file that cannot be read; runtime::SignalStop as above. A claim
// that fails is not an error here: ReportOutcome::tally names it.
ReportOutcome make_report(const ReportJob& job);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_REPORT_JOB_H_
