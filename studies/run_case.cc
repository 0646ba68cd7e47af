#include "studies/run_case.h"

#include <algorithm>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <memory>

#include "controller/device_frame.h"
#include "report/output_file.h"
#include "report/parallel.h"
#include "runtime/trace_writer.h"
#include "sim/mujoco_messages.h"
#include "studies/plot_svg.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace fs = std::filesystem;
namespace {


// trace.csv's layout for a loop: the controller's columns, the plant's,
// the script's phases, the simulated device's readings (joints only)
runtime::TraceLayout trace_layout(const ClosedLoop& loop) {
  runtime::TraceLayout l;
  l.controller = true;
  l.vm_dof = loop.controller().mechanism().dof();
  l.truth = true;
  for (const ScriptSegment& seg : loop.script().segments()) {
    l.phases.push_back(seg.name);
  }
  l.present = kStateJoints;
  return l;
}

}  // namespace

nlohmann::json claim_json(const Claim& c) {
  const auto opt = [](const auto& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  nlohmann::json sides = nlohmann::json::array();
  for (const Claim::Side& s : c.sides) {
    sides.push_back({{"where", s.where},
                     {"value", s.value},
                     {"pass", s.pass},
                     {"prediction", opt(s.prediction)},
                     {"matches_prediction", opt(s.matches_prediction)},
                     {"regime", s.regime},
                     {"mean_path_distance_mm", s.mean_path_distance_mm}});
  }
  return {{"name", c.name},         {"statement", c.statement},
          {"window", c.window},     {"value", c.value},
          {"comparison", c.comparison}, {"threshold", c.threshold},
          {"unit", c.unit},         {"samples", c.samples},
          {"mean_path_distance_mm", c.mean_path_distance_mm},
          {"pass", c.partial ? nlohmann::json("partial") : nlohmann::json(c.pass)},
          {"holds_where", c.partial ? nlohmann::json(c.holds_where)
                                    : nlohmann::json(nullptr)},
          {"sides", sides},
          {"prediction", c.prediction ? nlohmann::json(*c.prediction)
                                      : nlohmann::json(nullptr)},
          {"tolerance", c.prediction ? nlohmann::json(c.tolerance)
                                     : nlohmann::json(nullptr)},
          {"matches_prediction",
           c.matches_prediction ? nlohmann::json(*c.matches_prediction)
                                : nlohmann::json(nullptr)},
          {"prediction_note", c.prediction_note},
          {"saturated_fraction", c.saturated_fraction},
          {"regime", c.regime}};
}

nlohmann::json mujoco_warnings_json(
    const std::array<std::int64_t, mjNWARNING>& per_step,
    const MujocoWarningTally& messages) {
  nlohmann::json kinds = nlohmann::json::object();
  std::int64_t count = 0;
  for (int k = 0; k < mjNWARNING; ++k) {
    const std::int64_t n = per_step[static_cast<std::size_t>(k)];
    if (n > 0) kinds[mujoco_warning_name(k)] = n;
    count += n;
  }
  // what MuJoCo said besides its per-step warnings (those are counted above
  // at every step; it says each only once until the state is reset)
  const std::int64_t other = messages.count("other");
  if (other > 0) kinds["other"] = other;
  count += other;
  nlohmann::json texts = nlohmann::json::array();
  for (const MujocoWarningTally::Entry& e : messages.entries) {
    texts.push_back({{"kind", e.kind}, {"text", e.text}, {"count", e.count}});
  }
  return {{"count", count}, {"kinds", kinds}, {"messages", texts}};
}

nlohmann::json metrics_json(const RunMetrics& m) {
  return {{"ticks", m.ticks},
          {"rms_path_error_mm", m.rms_path_error_mm},
          {"max_path_error_mm", m.max_path_error_mm},
          {"rms_xv_error_mm", m.rms_xv_error_mm},
          {"mean_force_N", m.mean_force_N},
          {"rms_force_N", m.rms_force_N},
          {"max_force_N", m.max_force_N},
          {"time_on_path_s", m.time_on_path_s},
          {"on_path_within_mm", kOnPathMm},
          {"force_saturated_ticks", m.force_saturated_ticks},
          {"torque_saturated_ticks", m.torque_saturated_ticks},
          {"fault_ticks", m.fault_ticks},
          {"placement_not_converged_ticks", m.placement_not_converged_ticks},
          {"max_placement_iterations", m.max_placement_iterations}};
}

void check_trace_fits(const std::string& dir, std::int64_t ticks,
                      std::size_t columns, std::uintmax_t available_B) {
  // a tenth more for the summary and the figures
  const double need_B = 1.1 * runtime::trace_bytes_bound(ticks, columns);
  if (need_B <= static_cast<double>(available_B)) return;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "'%s': the trace of %lld ticks may need %.3g MB and the disk "
                "has %.3g MB free; shorten duration_s or free space",
                dir.c_str(), static_cast<long long>(ticks), need_B * 1e-6,
                static_cast<double>(available_B) * 1e-6);
  throw SimError(buf);
}

std::vector<std::string> trace_columns(const ClosedLoop& loop) {
  return runtime::trace_columns(trace_layout(loop));
}

namespace {

// every how many ticks a run keeps one for its claims, metrics and figures
int kept_every(const ClosedLoop& loop) {
  const std::int64_t n = loop.ticks_per_run();
  return static_cast<int>(
      std::max<std::int64_t>(1, (n + kMaxKeptTicks - 1) / kMaxKeptTicks));
}

// Whether the claims can read a tick at time t_s (studies/claims.cc reads
// the settled half of its windows' segments, and the whole sweep): the
// other sides' runs keep only those, which the claims then measure exactly
// as on every tick.
bool claims_read(const HandScript& script, double t_s) {
  const ScriptSegment& seg =
      script.segments()[static_cast<std::size_t>(script.segment_at(t_s))];
  return seg.name == "sweep" || t_s >= seg.settled_from_s();
}

// the loop to its end, with the reference controller where the case's
// claims compare with case 2's gains. Every tick goes to `trace` (if set) as
// it is made; every kept_every()-th is kept and returned, so memory stays
// flat however long the run; with `claims_only`, only those of them the
// claims read.
std::vector<TickRecord> run_to_end(ClosedLoop* loop, const StopFn& stop,
                                   runtime::TraceWriter* trace = nullptr,
                                   MetricsAccumulator* metrics = nullptr,
                                   bool claims_only = false) {
  const int thesis_case = loop->config().thesis_case;
  if (auto ref = reference_params(thesis_case, loop->controller_params())) {
    loop->set_reference(*ref);
  }
  const int every = kept_every(*loop);
  const HandScript& script = loop->script();
  const double T = loop->controller_params().servo_period_s;
  // room for what will be kept (with servo jitter the ticks' times are not
  // known ahead: the count at the nominal period, which the vector may
  // outgrow a little)
  std::int64_t expect = 0;
  for (std::int64_t k = 0; k < loop->ticks_per_run(); k += every) {
    if (!claims_only || claims_read(script, static_cast<double>(k) * T)) ++expect;
  }
  std::vector<TickRecord> rows;
  rows.reserve(static_cast<std::size_t>(std::min<std::int64_t>(kMaxKeptTicks + 1, expect + 1)));
  TickRecord row;
  std::int64_t n = 0;
  // a bad physics state (NaN, inf or beyond 1e10, which MuJoCo resets)
  // ends the run at the end of its tick: a failure (exit 1), not a result
  while (!loop->finished()) {
    if (stop && stop()) throw Interrupted();
    loop->tick(&row);
    loop->throw_if_physics_fault();
    if (trace) trace->add(row);
    if (metrics) metrics->add(row);
    if (n++ % every == 0 && (!claims_only || claims_read(script, row.t_s))) {
      rows.push_back(row);
    }
  }
  return rows;
}

// Refuses (SimError, before any simulation) a trace.csv the disk under
// `dir` cannot hold (check_trace_fits).
void check_space_for_trace(const std::string& dir, const ClosedLoop& loop) {
  std::error_code ec;
  fs::path probe = fs::absolute(dir, ec);
  while (!probe.empty() && !fs::exists(probe, ec)) probe = probe.parent_path();
  const fs::space_info space =
      fs::space(probe.empty() ? fs::path(".") : probe, ec);
  if (ec) return;  // unknown: the writes themselves will tell
  check_trace_fits(dir, loop.ticks_per_run(), trace_columns(loop).size(),
                   space.available);
}

// "name=a,b,c": a --set override with every digit of the values
std::string override_text(const char* field, std::initializer_list<double> v) {
  std::string s = std::string(field) + "=";
  char buf[32];
  for (double x : v) {
    std::snprintf(buf, sizeof buf, "%.17g", x);
    s += (s.back() == '=' ? "" : ",") + std::string(buf);
  }
  return s;
}

}  // namespace

CaseResult run_case(const std::string& name, const std::string& scene,
                    const std::vector<std::string>& overrides,
                    const std::string& out_dir,
                    const std::string& model_file, const StopFn& should_stop) {
  CaseResult result;
  result.name = name;
  result.scene = scene;

  // MuJoCo's warnings during this run (this thread's), for the summary
  MujocoWarningScope mujoco_messages;
  ClosedLoop loop(scene, overrides, omni_model_hook(model_file));
  const int thesis_case = loop.config().thesis_case;
  // the files go, as one set, into a private folder renamed into place when
  // all are written (the previous set, if any, is left whole until then);
  // trace.csv is written into it as the run goes
  std::unique_ptr<report::OutputSet> set;
  std::unique_ptr<runtime::TraceWriter> trace;
  if (!out_dir.empty()) {
    check_space_for_trace(out_dir, loop);
    set = std::make_unique<report::OutputSet>((fs::path(out_dir) / name).string());
    trace = std::make_unique<runtime::TraceWriter>(
        (fs::path(set->temp_dir()) / "trace.csv").string(),
        (fs::path(out_dir) / name / "trace.csv").string(), trace_layout(loop));
  }
  result.kept_every = kept_every(loop);
  const auto start = std::chrono::steady_clock::now();
  MetricsAccumulator metrics(loop);
  const std::vector<TickRecord> rows =
      run_to_end(&loop, should_stop, trace.get(), &metrics);
  const auto stop = std::chrono::steady_clock::now();
  if (trace) trace->close();
  result.wall_time_s = std::chrono::duration<double>(stop - start).count();
  result.simulated_s = loop.time_s();

  // over every tick; the claims over the kept ones
  result.metrics = metrics.result();
  result.claims = evaluate_claims(thesis_case, rows, loop);
  // the same script on the other sides of the pivot: mirrored left to right
  // (script_dir's and script_axis's x negated), from below the pivot
  // (script_below_dir, on both sides), and once more with the off-path holds
  // near the path (script_near_off_mm): a claim that holds on some of these
  // only is partial
  const ScriptSettings& script = loop.config().script;
  if (!result.claims.empty()) {
    const auto run_with = [&](std::vector<std::string> extra) {
      std::vector<std::string> o = overrides;
      o.insert(o.end(), extra.begin(), extra.end());
      ClosedLoop l(scene, o, omni_model_hook(model_file));
      const std::vector<TickRecord> r =
          run_to_end(&l, should_stop, nullptr, nullptr, /*claims_only=*/true);
      return evaluate_claims(thesis_case, r, l);
    };
    // a side's label from where its start pose is (device frame: x right,
    // y up) and how far off the path its off-path holds are
    const auto side = [](const Vec3& d, double off_mm, const char* more) {
      SideLabel l;
      l.where = d.x() < 0.0 ? "left of the pivot" : "right of the pivot";
      if (std::abs(d.y()) > 1e-9) l.where += d.y() > 0.0 ? ", above it" : ", below it";
      char buf[96];
      std::snprintf(buf, sizeof buf, ", off-path holds %g mm out%s", off_mm,
                    more);
      l.where_off_path = l.where + buf;
      return l;
    };
    const Vec3& axis = script.axis;
    // the start direction d (stylus axis `a` if set) and its mirror image
    const auto both_sides = [&](const Vec3& d, const Vec3& a, bool given,
                                std::vector<SideRun>* out) {
      for (const double sx : {1.0, -1.0}) {
        if (given && sx > 0.0) continue;  // the run already made
        if (sx < 0.0 && std::abs(d.x()) <= 1e-9) continue;  // no mirror image
        const Vec3 ds(sx * d.x(), d.y(), d.z());
        std::vector<std::string> o = {
            override_text("script_dir", {ds.x(), ds.y(), ds.z()})};
        if (!a.isZero(0.0)) {
          o.push_back(override_text("script_axis", {sx * a.x(), a.y(), a.z()}));
        }
        out->push_back({side(ds, script.off_mm, ""), run_with(o)});
      }
    };
    std::vector<SideRun> others;
    both_sides(script.dir, axis, /*given=*/true, &others);
    if (!script.below_dir.isZero(0.0)) {
      both_sides(script.below_dir, Vec3(axis.x(), -axis.y(), axis.z()),
                 /*given=*/false, &others);
    }
    if (script.near_off_mm > 0.0 && script.near_off_mm != script.off_mm) {
      others.push_back(
          {side(script.dir, script.near_off_mm, " (near the path)"),
           run_with({override_text("script_off_mm", {script.near_off_mm})}),
           /*off_path_only=*/true});
    }
    merge_sides(&result.claims, side(script.dir, script.off_mm, ""), others);
  }
  // a claim that holds on one side only is reported, not failed
  for (const Claim& c : result.claims) {
    result.all_claims_pass &= c.pass || c.partial;
    result.partial_claims += c.partial ? 1 : 0;
  }

  // the summary
  const RunMetrics& m = result.metrics;
  const mjModel* model = loop.model();
  nlohmann::json params = nlohmann::json::object();
  for (const FieldSpec& f : case_fields()) {
    nlohmann::json v;
    const ParamValue& given = loop.config().value(f);
    if (f.is_text) {
      v = given.text;
    } else if (f.size == 1) {
      v = given.numbers[0];
    } else {
      v = given.numbers;
    }
    params[f.name] = {{"value", v},
                      {"unit", f.unit},
                      {"source", value_source_name(given.source)}};
    if (f.reference != nullptr) params[f.name]["reference"] = f.reference;
    // the hand's values together as well, each with where it comes from
    if (std::strcmp(f.group, "hand") == 0) params["hand"][f.name] = params[f.name];
  }
  const nlohmann::json warnings =
      mujoco_warnings_json(loop.mujoco_warning_counts(), mujoco_messages.tally());
  nlohmann::json claims = nlohmann::json::array();
  for (const Claim& c : result.claims) claims.push_back(claim_json(c));
  static const char* const kIntegrators[] = {"Euler", "RK4", "implicit"};
  result.summary = {
      {"case", name},
      {"scene", scene},
      {"thesis_case", thesis_case},
      {"model", model_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(model_file)},
      {"simulated_s", result.simulated_s},
      {"wall_time_s", result.wall_time_s},
      {"realtime_factor", result.simulated_s / std::max(result.wall_time_s, 1e-9)},
      {"measured_every_ticks", result.kept_every},
      {"physics",
       {{"step_s", model->opt.timestep},
        {"substeps_per_tick", loop.substeps()},
        {"integrator", kIntegrators[std::clamp(model->opt.integrator, 0, 2)]},
        {"servo_period_s", loop.controller_params().servo_period_s},
        {"gravity_m_s2", {model->opt.gravity[0], model->opt.gravity[1], model->opt.gravity[2]}}}},
      {"parameters", params},
      {"metrics", metrics_json(m)},
      {"mujoco_warnings", warnings},
      {"claims", claims},
      {"all_claims_pass", result.all_claims_pass},
      {"partial_claims", result.partial_claims},
  };

  if (set) {
    const auto put_file = [&](const char* file, const std::string& text) {
      if (should_stop && should_stop()) throw Interrupted();
      set->write(file, text);
    };
    put_file("summary.json", result.summary.dump(2) + "\n");
    put_file("views.svg", views_svg(rows, loop));
    put_file("history.svg", history_svg(rows, loop));
    if (should_stop && should_stop()) throw Interrupted();
    set->commit();
  }
  return result;
}

void run_cases(std::vector<CaseJob>* jobs,
               const std::vector<std::string>& overrides,
               const std::string& out_dir, int threads,
               const std::string& model_file,
               const report::ProgressFn& progress, const StopFn& stop) {
  std::atomic<std::size_t> finished{0};
  report::parallel_for(jobs->size(), threads > 0 ? threads : report::core_count(),
               [&](std::size_t i) {
                 CaseJob& job = (*jobs)[i];
                 try {
                   job.result = run_case(job.name, job.scene, overrides, out_dir,
                                         model_file, stop);
                 } catch (const Interrupted& e) {
                   job.error = e.what();
                   job.interrupted = true;
                 } catch (const SimError& e) {
                   job.error = e.what();
                   job.bad_input = true;
                 } catch (const std::exception& e) {
                   job.error = e.what();
                 }
#ifdef __GLIBC__
                 // a case's rows and models are freed: give the pages back,
                 // rather than let each thread's arena keep its peak
                 malloc_trim(0);
#endif
                 if (progress) progress(++finished, jobs->size());
               });
}

}  // namespace vmh::studies
