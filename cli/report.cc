// vmhaptics report [--out DIR] [--reuse] [--jobs N] [--quick]
//
// One self-contained HTML page, DIR/report.html, with the thesis's figures
// for each of the seven cases, every measured claim, error against run time,
// the work-precision figure, the stability map and the extreme scenarios
// (thesis/report_html.h). It runs what it needs into DIR (the files `run
// --all --out DIR` and `study ... --out DIR/study` write) or, with --reuse,
// takes those already there and runs only what is missing. Prints one JSON
// object: {report, cases, claims_passed, claims_total, reused, ran, wall_s}.
// Exit codes: 0 written and every claim passed; 1 a claim failed (the page
// is still written) or a run failed; 2 bad usage; 130 / 143 SIGINT /
// SIGTERM: polled between the runs' ticks (as `run`), between the studies
// and between the cases' figures, and before report.html is written, so
// that DIR keeps only whole sets and files (the cases' sets complete
// before the signal, each study's files) and the previous report.html.
// A signal while report.html goes in lets it finish and then exits so.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "device/stop_signal.h"
#include "output/parallel.h"
#include "runtime/json_util.h"
#include "runtime/stop.h"
#include "studies/report_job.h"
#ifdef VMH_HAVE_VIZ
#include "sim/cases/case.h"
#include "viz/render.h"
#endif

#ifndef VMH_GIT_DESCRIBE
#define VMH_GIT_DESCRIBE "unknown"
#endif

namespace vmh::cli {
namespace {
namespace fs = std::filesystem;

#ifdef VMH_HAVE_VIZ
// One render per case, at the moment views.svg draws first: the middle of
// the settled half of the script's "off_out_misaligned" segment (the RM held
// off the path with the stylus misaligned), else the middle of the run.
// Written to DIR/<case>/render/ and embedded; without a display the page
// says why instead.
thesis::RenderFn case_renderer(const fs::path& dir) {
  return [dir](const std::string& case_name, const std::string& scene_path,
               std::string* why_not) -> std::optional<std::string> {
    try {
      double t_s = 0.0;
      {
        const sim::Case c = sim::load_case(scene_path, {});
        const auto& segs = c.script().segments();
        t_s = 0.5 * static_cast<double>(c.ticks_per_run()) *
              c.controller_params().servo_period_s;
        for (const sim::ScriptSegment& g : segs) {
          if (g.name == "off_out_misaligned") {
            t_s = 0.5 * (g.settled_from_s() + g.t1_s);
          }
        }
      }
      viz::RenderRequest req;
      req.scene_path = scene_path;
      req.name = case_name;
      req.times_s = {t_s};
      req.width_px = 800;
      req.height_px = 600;
      req.out_dir = (dir / case_name / "render").string();
      const std::vector<viz::RenderedImage> images = viz::render(req);
      const std::string png = thesis::read_file_text(images.at(0).path);
      if (png.empty()) {
        *why_not = "could not read " + images.at(0).path;
        return std::nullopt;
      }
      return png;
    } catch (const runtime::SignalStop&) {
      throw;  // not a reason to draw no picture: the report stops
    } catch (const std::exception& e) {
      *why_not = e.what();
      return std::nullopt;
    }
  };
}
#endif

struct ReportCli {
  std::string out = "out/report";
  bool reuse = false;
  int jobs = 0;  // 0: one per core
  bool quick = false;
};

std::string command_line(const ReportCli& o) {
  std::string s = "vmhaptics report --out " + o.out;
  if (o.reuse) s += " --reuse";
  if (o.jobs > 0) s += " --jobs " + std::to_string(o.jobs);
  if (o.quick) s += " --quick";
  return s;
}

// the job is studies::make_report (studies/report_job.h); this parses,
// calls and prints
void run(const ReportCli& o) {
  if (o.jobs < 0) throw UsageError("--jobs: must be >= 1 (0: one per core)");
  if (o.out.empty()) throw UsageError("--out: give a directory");
  // SIGINT / SIGTERM only set a flag (device/stop_signal.h), which the job
  // polls (see the exit codes above)
  StopSignals signals;
  studies::ReportJob job;
  job.out_dir = o.out;
  job.reuse = o.reuse;
  job.jobs = o.jobs > 0 ? o.jobs : output::core_count();
  job.quick = o.quick;
  job.command_line = command_line(o);
  job.version = VMH_VERSION;
  job.git_describe = VMH_GIT_DESCRIBE;
  job.generated_utc = utc_now();
  // the offscreen renderer exists where GLFW and OpenGL were found at build
  // time; without it (or without a display) each case says why
#ifdef VMH_HAVE_VIZ
  job.render = case_renderer(fs::path(o.out));
#else
  job.render = [](const std::string&, const std::string&, std::string* why_not) {
    *why_not = "this build has no renderer (GLFW or OpenGL was not found)";
    return std::optional<std::string>();
  };
#endif
  try {
    studies::make_report_folders(job);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--out: ") + e.what());
  }
  const studies::ReportOutcome r = studies::make_report(job);

  nlohmann::ordered_json out;
  out["report"] = r.page;
  out["cases"] = r.cases;
  out["claims_passed"] = r.tally.passed;
  out["claims_total"] = r.tally.total;
  out["claims_partial"] = r.tally.partial;
  out["reused"] = r.reused;
  out["ran"] = r.ran;
  out["wall_s"] = r.wall_s;
  std::cout << out.dump(2) << '\n' << std::flush;
  if (!r.tally.failed.empty()) {
    std::string failed;
    for (const std::string& f : r.tally.failed) failed += " " + f;
    throw std::runtime_error("report: thesis claim(s) not met:" + failed);
  }
}

}  // namespace

void register_report(CLI::App* app) {
  auto o = std::make_shared<ReportCli>();
  CLI::App* cmd = app->add_subcommand(
      "report",
      "one self-contained HTML page (DIR/report.html): per case the force "
      "along the path, the thesis's views and time histories, the "
      "parameters and every claim measured; error against run time, the "
      "work-precision figure, the stability map and the extreme scenarios. "
      "Runs what it needs into DIR: the full report took about 65 s on 2 "
      "shared cores, --quick about 20 s; --reuse a few seconds");
  cmd->add_option("--out", o->out,
                  "directory for report.html and the runs' files "
                  "(DIR/<case>/..., DIR/study/...); default out/report");
  cmd->add_flag("--reuse", o->reuse,
                "take the cases' and studies' files already in DIR (as `run "
                "--all --out DIR` and `study ... --out DIR/study` write them) "
                "and run only what is missing");
  cmd->add_option("--jobs", o->jobs,
                  "runs in parallel (default: one per core)");
  cmd->add_flag("--quick", o->quick,
                "a short precision study (1 s of case 1, three steps) and a "
                "coarse stability map (5 B values, h = 20 us); the cases and "
                "extreme scenarios in full, so the claims are the same");
  cmd->callback([o] {
    try {
      run(*o);
    } catch (const sim::SimError& e) {
      throw UsageError(std::string("report: ") + e.what());
    }
  });
}

}  // namespace vmh::cli
