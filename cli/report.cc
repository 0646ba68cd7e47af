// vmhaptics report [--out DIR] [--reuse] [--jobs N] [--quick]
//
// One self-contained HTML page, DIR/report.html, with the thesis's figures
// for each of the six cases, every measured claim, error against run time,
// the work-precision figure, the stability map and the extreme scenarios
// (studies/report_html.h). It runs what it needs into DIR (the files `run
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
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "device/stop_signal.h"
#include "runtime/json_util.h"
#include "runtime/stop.h"
#include "report/output_file.h"
#include "report/parallel.h"
#include "report/progress.h"
#include "studies/extremes_study.h"
#include "studies/precision_study.h"
#include "studies/report_html.h"
#include "studies/run_case.h"
#include "studies/stop.h"
#include "studies/stability_study.h"
#ifdef VMH_HAVE_VIZ
#include "sim/case.h"
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
studies::RenderFn case_renderer(const fs::path& dir) {
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
      const std::string png = studies::read_file_text(images.at(0).path);
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

// The stability map as scripts/demo runs it (a light slider near the Omni's
// first link: m 0.08 kg, b 0.028 N s/m, T 1 ms, h 5 us); --quick takes a
// coarser step and fewer B values. B up to 0.1 m/T, delays 0..2 ticks.
struct MapSetting {
  double physics_step_s;
  int points;
};
constexpr MapSetting kMapFull{5e-6, 11};
constexpr MapSetting kMapQuick{2e-5, 5};

// the precision study on case 1: the command line's defaults, or for
// --quick a short run over a three-rung ladder
constexpr double kQuickPrecisionDuration_s = 1.0;

std::string read_text(const fs::path& p) {
  return studies::read_file_text(p.string());
}

bool all_exist(const fs::path& dir, std::initializer_list<const char*> names) {
  std::error_code ec;
  for (const char* n : names) {
    if (!fs::is_regular_file(dir / n, ec)) return false;
  }
  return true;
}

std::string command_line(const ReportCli& o) {
  std::string s = "vmhaptics report --out " + o.out;
  if (o.reuse) s += " --reuse";
  if (o.jobs > 0) s += " --jobs " + std::to_string(o.jobs);
  if (o.quick) s += " --quick";
  return s;
}

studies::PrecisionOptions precision_options(const ReportCli& o,
                                            const fs::path& study_dir) {
  studies::PrecisionOptions p;
  p.scene = sim::resolve_scene("case1", &p.name);
  if (o.quick) {
    p.duration_s = kQuickPrecisionDuration_s;
    p.steps_s = {1e-3, 2e-4, 5e-5};
    p.reference_step_s = 1e-5;
    p.reference_check_step_s = 2e-5;
    p.min_timing_s = 0.05;
    p.max_repeats = 2;
  }
  p.out_dir = study_dir.string();
  return p;
}

studies::StabilityOptions map_options(const ReportCli& o,
                                      const fs::path& study_dir, int jobs) {
  const MapSetting m = o.quick ? kMapQuick : kMapFull;
  studies::StabilityOptions so;
  so.model_path = studies::slider_model_path(sim::models_dir());
  so.params.mass_kg = 0.08;
  so.params.damping_Ns_per_m = 0.028;
  so.params.servo_period_s = 1e-3;
  so.params.physics_step_s = m.physics_step_s;
  const double b_max = 0.1 * so.params.mass_kg / so.params.servo_period_s;
  for (int i = 0; i < m.points; ++i) {
    so.map_virtual_damping_Ns_per_m.push_back(b_max * i / (m.points - 1));
  }
  so.map_delay_ticks = {0, 1, 2};
  so.jobs = jobs;
  so.out_dir = study_dir.string();
  return so;
}

std::string map_note(const studies::StabilityOptions& so) {
  std::ostringstream s;
  s << "slider m = " << so.params.mass_kg << " kg, b = "
    << so.params.damping_Ns_per_m << " N s/m, T = "
    << so.params.servo_period_s << " s, h = " << so.params.physics_step_s
    << " s; B from 0 to " << so.map_virtual_damping_Ns_per_m.back()
    << " N s/m in " << so.map_virtual_damping_Ns_per_m.size()
    << " values, delays 0, 1 and 2 ticks";
  return s.str();
}

// One of the studies, asked to stop when a signal came (it polls the
// flag inside its runs and throws Interrupted before writing): the stop
// named as report's, with what report keeps
template <typename F>
void run_stoppable(F study, const std::string& kept) {
  try {
    study();
  } catch (const studies::Interrupted&) {
    runtime::throw_if_stopped("report", kept);
    throw;
  }
}

void run(const ReportCli& o) {
  if (o.jobs < 0) throw UsageError("--jobs: must be >= 1 (0: one per core)");
  if (o.out.empty()) throw UsageError("--out: give a directory");
  // SIGINT / SIGTERM only set a flag (device/stop_signal.h); see the exit
  // codes above for where it is polled
  StopSignals signals;
  const std::string kept = "; report.html not written (the sets and files "
                           "already complete are kept)";
  const auto start = std::chrono::steady_clock::now();
  const int jobs = o.jobs > 0 ? o.jobs : report::core_count();
  const fs::path dir(o.out);
  const fs::path study_dir = dir / "study";
  std::error_code ec;
  fs::create_directories(study_dir, ec);
  if (ec || !fs::is_directory(study_dir)) {
    throw UsageError("--out: cannot create directory '" + study_dir.string() + "'");
  }

  // what is there already (with --reuse) and what must run
  std::vector<std::string> reused, ran;
  std::vector<studies::CaseJob> cases;
  for (const sim::CaseEntry& c : sim::thesis_cases()) {
    if (o.reuse && all_exist(dir / c.name, {"summary.json", "trace.csv",
                                            "views.svg", "history.svg"})) {
      reused.push_back(c.name);
    } else {
      std::string name;
      cases.push_back({c.name, sim::resolve_scene(c.name, &name), {}, {}, false});
      ran.push_back(c.name);
    }
  }
  auto want = [&](const char* label, std::initializer_list<const char*> files) {
    const bool have = o.reuse && all_exist(study_dir, files);
    (have ? reused : ran).push_back(label);
    return !have;
  };
  const bool run_extremes = want("extremes", {"extremes.json", "extremes.svg"});
  const bool run_map = want("stability_map", {"stability_map.csv", "stability_map.svg"});
  const bool run_precision =
      want("precision", {"precision.csv", "precision.svg", "precision_order.svg"});

  const studies::PrecisionOptions precision = precision_options(o, study_dir);
  const studies::StabilityOptions map = map_options(o, study_dir, jobs);
  {
    // one bar over the whole job; each study corrects its part's estimate
    report::Progress bar("report", 0);
    const std::size_t p_cases = bar.add_part(cases.size());
    const std::size_t p_ex =
        bar.add_part(run_extremes ? studies::extreme_scenarios().size() : 0);
    const std::size_t p_map = bar.add_part(
        run_map ? map.map_virtual_damping_Ns_per_m.size() * 3 : 0);
    const std::size_t p_prec = bar.add_part(
        run_precision ? precision.steps_s.size() * precision.integrators.size() + 1 : 0);
    if (!cases.empty()) {
      studies::run_cases(&cases, {}, dir.string(), jobs, "", bar.part(p_cases),
                         [] { return stop_requested(); });
      runtime::throw_if_stopped("report", kept);
      for (const studies::CaseJob& j : cases) {
        if (!j.error.empty()) throw std::runtime_error("report: " + j.name + ": " + j.error);
      }
    }
    runtime::throw_if_stopped("report", kept);
    if (run_extremes) {
      studies::ExtremesOptions ex;
      ex.out_dir = study_dir.string();
      ex.jobs = jobs;
      ex.progress = bar.part(p_ex);
      ex.should_stop = [] { return stop_requested(); };
      run_stoppable([&] { studies::run_extremes_study(ex); }, kept);
    }
    runtime::throw_if_stopped("report", kept);
    if (run_map) {
      studies::StabilityOptions m = map;
      m.progress = bar.part(p_map);
      m.should_stop = [] { return stop_requested(); };
      run_stoppable([&] { studies::run_stability_study(m); }, kept);
    }
    runtime::throw_if_stopped("report", kept);
    if (run_precision) {
      // alone, so that its timings do not compete with other runs
      studies::PrecisionOptions p = precision;
      p.progress = bar.part(p_prec);
      p.should_stop = [] { return stop_requested(); };
      run_stoppable([&] { studies::run_precision_study(p); }, kept);
    }
  }

  studies::ReportInputs in;
  // the offscreen renderer exists where GLFW and OpenGL were found at build
  // time; without it (or without a display) each case says why
#ifdef VMH_HAVE_VIZ
  const studies::RenderFn render = case_renderer(dir);
#else
  const studies::RenderFn render = [](const std::string&, const std::string&,
                                      std::string* why_not) {
    *why_not = "this build has no renderer (GLFW or OpenGL was not found)";
    return std::optional<std::string>();
  };
#endif
  for (const sim::CaseEntry& c : sim::thesis_cases()) {
    runtime::throw_if_stopped("report", kept);
    try {
      in.cases.push_back(studies::load_report_case(dir.string(), c.name, render));
    } catch (const runtime::SignalStop&) {
      runtime::throw_if_stopped("report", kept);  // named as report's
      throw;
    }
    // the force field and the thesis's figures exist only here: kept beside
    // the case's other SVGs,
    // so that they can be opened (and compared) standalone
    report::write_file_in((dir / c.name).string(), "force_field.svg",
                          in.cases.back().force_field_svg);
    report::write_file_in((dir / c.name).string(), "thesis.svg",
                          in.cases.back().thesis_svg);
  }
  studies::ReportStudies& st = in.studies;
  st.precision_case = precision.name;
  st.precision_csv = read_text(study_dir / "precision.csv");
  st.precision_svg = read_text(study_dir / "precision.svg");
  st.precision_order_svg = read_text(study_dir / "precision_order.svg");
  st.stability_note = map_note(map);
  st.stability_map_csv = read_text(study_dir / "stability_map.csv");
  st.stability_map_svg = read_text(study_dir / "stability_map.svg");
  try {
    st.extremes = nlohmann::json::parse(read_text(study_dir / "extremes.json"));
  } catch (const std::exception& e) {
    throw std::runtime_error((study_dir / "extremes.json").string() + ": " + e.what());
  }
  st.extremes_svg = read_text(study_dir / "extremes.svg");

  studies::ReportHeader& h = in.header;
  h.version = VMH_VERSION;
  h.git_describe = VMH_GIT_DESCRIBE;
  h.generated_utc = utc_now();
  h.command_line = command_line(o);
  h.cores = report::core_count();
  h.reused = reused;
  h.ran = ran;
  h.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string html = studies::report_html(in);
  runtime::throw_if_stopped("report", kept);
  const std::string page = report::write_file_in(dir.string(), "report.html", html);
  // a signal while the page went in: it is whole, and the exit says so
  runtime::throw_if_stopped("report", "; " + page + " was already written whole");

  const studies::ClaimTally tally = studies::tally_claims(in.cases);
  nlohmann::ordered_json out;
  out["report"] = page;
  nlohmann::ordered_json names = nlohmann::ordered_json::array();
  for (const studies::ReportCase& c : in.cases) names.push_back(c.name);
  out["cases"] = names;
  out["claims_passed"] = tally.passed;
  out["claims_total"] = tally.total;
  out["claims_partial"] = tally.partial;
  out["reused"] = reused;
  out["ran"] = ran;
  out["wall_s"] = h.wall_s;
  std::cout << out.dump(2) << '\n' << std::flush;
  if (!tally.failed.empty()) {
    std::string failed;
    for (const std::string& f : tally.failed) failed += " " + f;
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
