#include "studies/report_job.h"

#include <chrono>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "device/stop_signal.h"
#include "output/output_file.h"
#include "output/parallel.h"
#include "output/progress.h"
#include "runtime/stop.h"
#include "sim/cases/case_catalogue.h"
#include "studies/extremes_study.h"
#include "studies/precision_study.h"
#include "thesis/run_case.h"
#include "studies/stability_study.h"

namespace vmh::studies {
namespace {
namespace fs = std::filesystem;

// The stability map as scripts/demo runs it (a light slider near the Omni's
// first link: m 0.08 kg, b 0.028 N s/m, T 1 ms, h 5 us); quick takes a
// coarser step and fewer B values. B up to 0.1 m/T, delays 0..2 ticks.
struct MapSetting {
  double physics_step_s;
  int points;
};
constexpr MapSetting kMapFull{5e-6, 11};
constexpr MapSetting kMapQuick{2e-5, 5};

// the precision study on case 1: the command line's defaults, or when
// quick a short run over a three-rung ladder
constexpr double kQuickPrecisionDuration_s = 1.0;

bool rj_all_exist(const fs::path& dir, std::initializer_list<const char*> names) {
  std::error_code ec;
  for (const char* n : names) {
    if (!fs::is_regular_file(dir / n, ec)) return false;
  }
  return true;
}

PrecisionOptions rj_precision_options(const ReportJob& job,
                                      const fs::path& study_dir) {
  PrecisionOptions p;
  p.scene = sim::resolve_scene("case1", &p.name);
  if (job.quick) {
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

StabilityOptions rj_map_options(const ReportJob& job, const fs::path& study_dir) {
  const MapSetting m = job.quick ? kMapQuick : kMapFull;
  StabilityOptions so;
  so.model_path = slider_model_path(sim::models_dir());
  so.params.mass_kg = 0.08;
  so.params.damping_Ns_per_m = 0.028;
  so.params.servo_period_s = 1e-3;
  so.params.physics_step_s = m.physics_step_s;
  const double b_max = 0.1 * so.params.mass_kg / so.params.servo_period_s;
  for (int i = 0; i < m.points; ++i) {
    so.map_virtual_damping_Ns_per_m.push_back(b_max * i / (m.points - 1));
  }
  so.map_delay_ticks = {0, 1, 2};
  so.jobs = job.jobs;
  so.out_dir = study_dir.string();
  return so;
}

std::string rj_map_note(const StabilityOptions& so) {
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
// flag inside its runs and throws runtime::Interrupted before writing): the
// stop named as report's, with what report keeps
template <typename F>
void rj_run_stoppable(F study, const std::string& kept) {
  try {
    study();
  } catch (const runtime::Interrupted&) {
    runtime::throw_if_stopped("report", kept);
    throw;
  }
}

bool rj_stop() { return stop_requested(); }

// what is there already (with reuse) and what must run
struct RjPlan {
  std::vector<std::string> reused, ran;
  std::vector<thesis::CaseJob> cases;
  bool extremes = false, map = false, precision = false;
};

RjPlan rj_plan(const ReportJob& job, const fs::path& dir, const fs::path& study_dir) {
  RjPlan plan;
  for (const sim::CaseEntry& c : sim::case_catalogue()) {
    if (job.reuse && rj_all_exist(dir / c.name, {"summary.json", "trace.csv",
                                                 "views.svg", "history.svg"})) {
      plan.reused.push_back(c.name);
    } else {
      std::string name;
      plan.cases.push_back({c.name, sim::resolve_scene(c.name, &name), {}, {}, false});
      plan.ran.push_back(c.name);
    }
  }
  auto want = [&](const char* label, std::initializer_list<const char*> files) {
    const bool have = job.reuse && rj_all_exist(study_dir, files);
    (have ? plan.reused : plan.ran).push_back(label);
    return !have;
  };
  plan.extremes = want("extremes", {"extremes.json", "extremes.svg"});
  plan.map = want("stability_map", {"stability_map.csv", "stability_map.svg"});
  plan.precision =
      want("precision", {"precision.csv", "precision.svg", "precision_order.svg"});
  return plan;
}

// runs what the plan says must run, under one progress bar
void rj_run(const ReportJob& job, RjPlan* plan, const fs::path& dir,
            const PrecisionOptions& precision, const StabilityOptions& map,
            const std::string& kept) {
  // one bar over the whole job; each study corrects its part's estimate
  output::Progress bar("report", 0);
  const std::size_t p_cases = bar.add_part(plan->cases.size());
  const std::size_t p_ex =
      bar.add_part(plan->extremes ? extreme_scenarios().size() : 0);
  const std::size_t p_map =
      bar.add_part(plan->map ? map.map_virtual_damping_Ns_per_m.size() * 3 : 0);
  const std::size_t p_prec = bar.add_part(
      plan->precision ? precision.steps_s.size() * precision.integrators.size() + 1 : 0);
  if (!plan->cases.empty()) {
    run_cases(&plan->cases, {}, dir.string(), job.jobs, "", bar.part(p_cases), rj_stop);
    runtime::throw_if_stopped("report", kept);
    for (const thesis::CaseJob& j : plan->cases) {
      if (!j.error.empty()) throw std::runtime_error("report: " + j.name + ": " + j.error);
    }
  }
  runtime::throw_if_stopped("report", kept);
  if (plan->extremes) {
    ExtremesOptions ex;
    ex.out_dir = map.out_dir;
    ex.jobs = job.jobs;
    ex.progress = bar.part(p_ex);
    ex.should_stop = rj_stop;
    rj_run_stoppable([&] { run_extremes_study(ex); }, kept);
  }
  runtime::throw_if_stopped("report", kept);
  if (plan->map) {
    StabilityOptions m = map;
    m.progress = bar.part(p_map);
    m.should_stop = rj_stop;
    rj_run_stoppable([&] { run_stability_study(m); }, kept);
  }
  runtime::throw_if_stopped("report", kept);
  if (plan->precision) {
    // alone, so that its timings do not compete with other runs
    PrecisionOptions p = precision;
    p.progress = bar.part(p_prec);
    p.should_stop = rj_stop;
    rj_run_stoppable([&] { run_precision_study(p); }, kept);
  }
}

// the studies' files, as the page shows them
thesis::ReportStudies rj_studies(const fs::path& study_dir,
                                 const PrecisionOptions& precision,
                                 const StabilityOptions& map) {
  auto text = [&](const char* name) {
    return thesis::read_file_text((study_dir / name).string());
  };
  thesis::ReportStudies st;
  st.precision_case = precision.name;
  st.precision_csv = text("precision.csv");
  st.precision_svg = text("precision.svg");
  st.precision_order_svg = text("precision_order.svg");
  st.stability_note = rj_map_note(map);
  st.stability_map_csv = text("stability_map.csv");
  st.stability_map_svg = text("stability_map.svg");
  try {
    st.extremes = nlohmann::json::parse(text("extremes.json"));
  } catch (const std::exception& e) {
    throw std::runtime_error((study_dir / "extremes.json").string() + ": " + e.what());
  }
  st.extremes_svg = text("extremes.svg");
  return st;
}

}  // namespace

void make_report_folders(const ReportJob& job) {
  const fs::path study_dir = fs::path(job.out_dir) / "study";
  std::error_code ec;
  fs::create_directories(study_dir, ec);
  if (ec || !fs::is_directory(study_dir)) {
    throw std::invalid_argument("cannot create directory '" + study_dir.string() + "'");
  }
}

ReportOutcome make_report(const ReportJob& job) {
  if (job.jobs < 1) {
    throw std::invalid_argument("report: jobs must be >= 1, got " +
                                std::to_string(job.jobs));
  }
  if (job.out_dir.empty()) throw std::invalid_argument("report: no output folder");
  if (!job.render) throw std::invalid_argument("report: no renderer given");
  const std::string kept = "; report.html not written (the sets and files "
                           "already complete are kept)";
  const auto start = std::chrono::steady_clock::now();
  const fs::path dir(job.out_dir);
  const fs::path study_dir = dir / "study";
  make_report_folders(job);

  RjPlan plan = rj_plan(job, dir, study_dir);
  const PrecisionOptions precision = rj_precision_options(job, study_dir);
  const StabilityOptions map = rj_map_options(job, study_dir);
  rj_run(job, &plan, dir, precision, map, kept);

  thesis::ReportInputs in;
  for (const sim::CaseEntry& c : sim::case_catalogue()) {
    runtime::throw_if_stopped("report", kept);
    try {
      in.cases.push_back(
          thesis::load_report_case(dir.string(), c.name, job.render));
    } catch (const runtime::SignalStop&) {
      runtime::throw_if_stopped("report", kept);  // named as report's
      throw;
    }
    // the force field and the thesis's figures exist only here: kept beside
    // the case's other SVGs, so that they can be opened (and compared)
    // standalone
    output::write_file_in((dir / c.name).string(), "force_field.svg",
                          in.cases.back().force_field_svg);
    output::write_file_in((dir / c.name).string(), "thesis.svg",
                          in.cases.back().thesis_svg);
  }
  in.studies = rj_studies(study_dir, precision, map);

  thesis::ReportHeader& h = in.header;
  h.version = job.version;
  h.git_describe = job.git_describe;
  h.generated_utc = job.generated_utc;
  h.command_line = job.command_line;
  h.cores = output::core_count();
  h.reused = plan.reused;
  h.ran = plan.ran;
  h.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string html = report_html(in);
  runtime::throw_if_stopped("report", kept);
  ReportOutcome out;
  out.page = output::write_file_in(dir.string(), "report.html", html);
  // a signal while the page went in: it is whole, and the exit says so
  runtime::throw_if_stopped("report", "; " + out.page + " was already written whole");

  for (const thesis::ReportCase& c : in.cases) out.cases.push_back(c.name);
  out.reused = plan.reused;
  out.ran = plan.ran;
  out.tally = tally_claims(in.cases);
  out.wall_s = h.wall_s;
  return out;
}

}  // namespace vmh::studies
