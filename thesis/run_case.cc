#include "thesis/run_case.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <mutex>

#include "controller/device_frame.h"
#include "output/output_file.h"
#include "output/parallel.h"
#include "runtime/trace_writer.h"
#include "sim/mujoco_messages.h"
#include "thesis/plot_svg.h"
#include "thesis/side_runs.h"

namespace vmh::thesis {
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

// The rows of this thread's runs (0: the main run's, 1: a side's), kept
// from one run to the next: a 20 s case keeps 20,000 rows (31 MB), and
// fresh pages for every run, which the kernel must zero, cost more than
// the simulation's copying of them (a fifth of run --all's time before)
std::vector<TickRecord>& row_buffer(int which) {
  static thread_local std::array<std::vector<TickRecord>, 2> buffers;
  std::vector<TickRecord>& b = buffers[static_cast<std::size_t>(which)];
  b.clear();
  return b;
}

// the main run to its end: every tick goes to `trace` (if set) and
// `metrics` as it is made; every kept_every()-th is kept in *rows, so
// memory stays flat however long the run
void run_to_end(ClosedLoop* loop, const runtime::StopFn& stop,
                runtime::TraceWriter* trace, MetricsAccumulator* metrics,
                std::vector<TickRecord>* rows) {
  use_reference_gains(loop);
  const int every = kept_every(*loop);
  // room for what will be kept (with servo jitter the ticks' times are not
  // known ahead: the count at the nominal period, which the vector may
  // outgrow a little)
  const std::int64_t expect = (loop->ticks_per_run() + every - 1) / every;
  reserve_rows(rows, static_cast<std::size_t>(
                        std::min<std::int64_t>(kMaxKeptTicks + 1, expect + 1)));
  TickRecord spare;
  std::int64_t n = 0;
  // a bad physics state (NaN, inf or beyond 1e10, which MuJoCo resets)
  // ends the run at the end of its tick: a failure (exit 1), not a result
  while (!loop->finished()) {
    if (stop && stop()) throw runtime::Interrupted();
    // a kept tick is recorded in its place among the rows, not copied
    // there (1.5 kB a tick)
    TickRecord& row = n++ % every == 0 ? rows->emplace_back() : spare;
    loop->tick(&row);
    loop->throw_if_physics_fault();
    if (trace) trace->add(row);
    if (metrics) metrics->add(row);
  }
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

namespace {

// A side's label from where its start pose is (device frame: x right, y up)
// and how far off the path its off-path holds are.
SideLabel side_label(const Vec3& d, double off_mm, const char* more) {
  SideLabel l;
  l.where = d.x() < 0.0 ? "left of the pivot" : "right of the pivot";
  if (std::abs(d.y()) > 1e-9) l.where += d.y() > 0.0 ? ", above it" : ", below it";
  char buf[96];
  std::snprintf(buf, sizeof buf, ", off-path holds %g mm out%s", off_mm, more);
  l.where_off_path = l.where + buf;
  return l;
}

// One case and all its runs: the main run (the case as given, the one
// that writes trace.csv and the figures) and the other sides of its claims
// (thesis/side_runs.h). Each run is a job that any thread may take
// (run_cases() puts every run of every case in one pool, so that the
// cores stay busy to the end); finish() makes the summary and the files
// once all are done. Construction loads and checks everything (bad input
// throws SimError here, before any simulation).
class CaseWork {
 public:
  CaseWork(const std::string& name, const std::string& scene,
           const std::vector<std::string>& overrides,
           const std::string& out_dir, const std::string& model_file,
           const CaseRunOptions& options)
      : name_(name), scene_(scene), overrides_(overrides), out_dir_(out_dir),
        model_file_(model_file), options_(options),
        // compiled without what is only drawn: nothing here renders
        compiled_(load_scene_model(scene, omni_model_hook(model_file),
                                   /*headless=*/true)),
        loop_(std::make_unique<ClosedLoop>(scene, *compiled_, overrides)) {
    result_.name = name;
    result_.scene = scene;
    thesis_case_ = loop_->config().thesis_case;
    // the files go, as one set, into a private folder renamed into place
    // when all are written (the previous set, if any, is left whole until
    // then); trace.csv is written into it as the run goes
    if (!out_dir.empty()) {
      check_space_for_trace(out_dir, *loop_);
      set_ = std::make_unique<output::OutputSet>((fs::path(out_dir) / name).string());
      trace_ = std::make_unique<runtime::TraceWriter>(
          (fs::path(set_->temp_dir()) / "trace.csv").string(),
          (fs::path(out_dir) / name / "trace.csv").string(), trace_layout(*loop_));
    }
    plan_sides();
    remaining_ = static_cast<int>(runs());
  }

  // The case loaded, with what MuJoCo said while loading it (for the
  // summary; each run keeps its own).
  static std::unique_ptr<CaseWork> load(
      const std::string& name, const std::string& scene,
      const std::vector<std::string>& overrides, const std::string& out_dir,
      const std::string& model_file, const CaseRunOptions& options) {
    MujocoWarningScope load_messages;
    auto work = std::make_unique<CaseWork>(name, scene, overrides, out_dir,
                                           model_file, options);
    work->messages_.merge(load_messages.tally());
    return work;
  }

  // the runs: 0 the main run, 1.. the sides
  std::size_t runs() const { return 1 + sides_.size(); }

  // Runs run i (any thread; each run has its own model and data). Returns
  // true when it was the case's last run to end.
  bool run(std::size_t i, const runtime::StopFn& stop) {
    // once a run of the case has failed, the case has: its other runs end
    if (failed_) return --remaining_ == 0;
    try {
      MujocoWarningScope messages;
      if (i == 0) {
        run_main(stop);
      } else {
        run_other_side(i - 1, stop);
      }
      std::lock_guard<std::mutex> lock(mutex_);
      messages_.merge(messages.tally());
    } catch (...) {
      fail(std::current_exception());
    }
    return --remaining_ == 0;
  }

  // After every run: the claims' sides merged, the summary, the files.
  // Rethrows the first failed run's exception, as it was thrown
  // (runtime::Interrupted, SimError, PhysicsError, ...: run_case() documents
  // them).
  CaseResult finish(const runtime::StopFn& stop) {
    if (error_) std::rethrow_exception(error_);
    if (!result_.claims.empty()) {
      std::vector<SideRun> others;
      for (const Side& s : sides_) {
        others.push_back({s.label, s.claims, s.off_path_only});
      }
      merge_sides(&result_.claims, first_label_, others);
    }
    // a claim that holds on one side only is reported, not failed
    for (const Claim& c : result_.claims) {
      result_.all_claims_pass &= c.pass || c.partial;
      result_.partial_claims += c.partial ? 1 : 0;
    }
    make_summary();
    if (set_) {
      const auto put_file = [&](const char* file, const std::string& text) {
        if (stop && stop()) throw runtime::Interrupted();
        set_->write(file, text);
      };
      put_file("summary.json", result_.summary.dump(2) + "\n");
      put_file("views.svg", views_);
      put_file("history.svg", history_);
      if (stop && stop()) throw runtime::Interrupted();
      set_->commit();
    }
    return std::move(result_);
  }

 private:
  // one of the claims' other sides
  struct Side {
    SideLabel label;
    std::vector<std::string> extra;  // the overrides that make it
    bool off_path_only = false;
    std::vector<Claim> claims;
    nlohmann::json stats;
  };

  // The same script on the other sides of the pivot: mirrored left to right
  // (script_dir's and script_axis's x negated), from below the pivot
  // (script_below_dir, on both sides), and once more with the off-path
  // holds near the path (script_near_off_mm): a claim that holds on some
  // of these only is partial. A case without claims has no sides.
  void plan_sides() {
    const ScriptSettings& script = loop_->config().script;
    first_label_ = side_label(script.dir, script.off_mm, "");
    // the claims' windows, which say what each side must simulate
    window_claims_ = evaluate_claims(thesis_case_, {}, loop_->the_case());
    if (window_claims_.empty()) return;
    const Vec3& axis = script.axis;
    // the start direction d (stylus axis `a` if set) and its mirror image
    const auto both_sides = [&](const Vec3& d, const Vec3& a, bool given) {
      for (const double sx : {1.0, -1.0}) {
        if (given && sx > 0.0) continue;  // the main run
        if (sx < 0.0 && std::abs(d.x()) <= 1e-9) continue;  // no mirror image
        const Vec3 ds(sx * d.x(), d.y(), d.z());
        Side side;
        side.label = side_label(ds, script.off_mm, "");
        side.extra = {override_text("script_dir", {ds.x(), ds.y(), ds.z()})};
        if (!a.isZero(0.0)) {
          side.extra.push_back(
              override_text("script_axis", {sx * a.x(), a.y(), a.z()}));
        }
        sides_.push_back(std::move(side));
      }
    };
    both_sides(script.dir, axis, /*given=*/true);
    if (!script.below_dir.isZero(0.0)) {
      both_sides(script.below_dir, Vec3(axis.x(), -axis.y(), axis.z()),
                 /*given=*/false);
    }
    if (script.near_off_mm > 0.0 && script.near_off_mm != script.off_mm) {
      Side side;
      side.label = side_label(script.dir, script.near_off_mm, " (near the path)");
      side.extra = {override_text("script_off_mm", {script.near_off_mm})};
      side.off_path_only = true;
      sides_.push_back(std::move(side));
    }
  }

  void run_main(const runtime::StopFn& stop) {
    ClosedLoop& loop = *loop_;
    result_.kept_every = kept_every(loop);
    const auto start = std::chrono::steady_clock::now();
    MetricsAccumulator metrics(loop.the_case());
    std::vector<TickRecord>& rows = row_buffer(0);
    run_to_end(&loop, stop, trace_.get(), &metrics, &rows);
    const auto end = std::chrono::steady_clock::now();
    if (trace_) trace_->close();
    result_.wall_time_s = std::chrono::duration<double>(end - start).count();
    result_.simulated_s = loop.time_s();
    // over every tick; the claims and figures over the kept ones, made now
    // so that the rows' memory goes to this thread's next run
    result_.metrics = metrics.result();
    result_.claims = evaluate_claims(thesis_case_, rows, loop.the_case());
    if (set_) {
      views_ = views_svg(rows, loop.the_case());
      history_ = history_svg(rows, loop.the_case());
    }
    std::lock_guard<std::mutex> lock(mutex_);
    add_warnings(loop);
  }

  void run_other_side(std::size_t k, const runtime::StopFn& stop) {
    Side& side = sides_[k];
    std::vector<std::string> o = overrides_;
    o.insert(o.end(), side.extra.begin(), side.extra.end());
    ClosedLoop l(scene_, *compiled_, o);
    const SidePlan plan = plan_side(l.script(), window_claims_, side.off_path_only);
    std::unique_ptr<runtime::TraceWriter> side_trace;
    std::string file;
    if (set_ && options_.trace_sides) {
      file = "trace_side_" + std::to_string(k + 1) + ".csv";
      side_trace = std::make_unique<runtime::TraceWriter>(
          (fs::path(set_->temp_dir()) / file).string(),
          (fs::path(out_dir_) / name_ / file).string(), trace_layout(l));
    }
    SideStats st;
    std::vector<TickRecord>& rows = row_buffer(1);
    run_side(&l, plan, options_.sides, stop, side_trace.get(), &st, &rows);
    if (side_trace) side_trace->close();
    side.claims = evaluate_claims(thesis_case_, rows, l.the_case());
    side.stats = {{"where", side.off_path_only ? side.label.where_off_path
                                               : side.label.where},
                  {"overrides", side.extra},
                  {"physics_s", st.physics_s},
                  {"script_s", st.script_s},
                  {"ticks", st.ticks},
                  {"holds_settled", st.holds_settled},
                  {"wall_time_s", st.wall_time_s},
                  {"trace", file.empty() ? nlohmann::json(nullptr)
                                         : nlohmann::json(file)}};
    std::lock_guard<std::mutex> lock(mutex_);
    add_warnings(l);
  }

  // MuJoCo's per-step warnings of a run, added to the case's (under mutex_)
  void add_warnings(const ClosedLoop& l) {
    for (std::size_t k = 0; k < warning_counts_.size(); ++k) {
      warning_counts_[k] += l.mujoco_warning_counts()[k];
    }
  }

  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex_);
    failed_ = true;
    if (!error_) error_ = e;  // the first error is the case's
  }

  void make_summary() {
    const ClosedLoop& loop = *loop_;
    const RunMetrics& m = result_.metrics;
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
    nlohmann::json claims = nlohmann::json::array();
    for (const Claim& c : result_.claims) claims.push_back(claim_json(c));
    nlohmann::json side_runs = nlohmann::json::array();
    for (const Side& s : sides_) side_runs.push_back(s.stats);
    static const char* const kIntegrators[] = {"Euler", "RK4", "implicit"};
    result_.summary = {
        {"case", name_},
        {"scene", scene_},
        {"thesis_case", thesis_case_},
        {"model", model_file_.empty() ? nlohmann::json(nullptr)
                                      : nlohmann::json(model_file_)},
        {"simulated_s", result_.simulated_s},
        {"wall_time_s", result_.wall_time_s},
        {"realtime_factor",
         result_.simulated_s / std::max(result_.wall_time_s, 1e-9)},
        {"measured_every_ticks", result_.kept_every},
        {"physics",
         {{"step_s", model->opt.timestep},
          {"substeps_per_tick", loop.substeps()},
          {"integrator", kIntegrators[std::clamp(model->opt.integrator, 0, 2)]},
          {"servo_period_s", loop.controller_params().servo_period_s},
          {"gravity_m_s2",
           {model->opt.gravity[0], model->opt.gravity[1], model->opt.gravity[2]}}}},
        {"parameters", params},
        {"metrics", metrics_json(m)},
        {"mujoco_warnings", mujoco_warnings_json(warning_counts_, messages_)},
        {"claims", claims},
        {"sides", {{"mode", side_mode_name(options_.sides)},
                   {"settled_speed_rad_s", kSettledSpeedRadS},
                   {"settled_ticks", kSettledTicks},
                   {"measured_ticks", kMeasuredTicks},
                   {"runs", side_runs}}},
        {"all_claims_pass", result_.all_claims_pass},
        {"partial_claims", result_.partial_claims},
    };
  }

  std::string name_, scene_;
  std::vector<std::string> overrides_;
  std::string out_dir_, model_file_;
  CaseRunOptions options_;
  ModelPtr compiled_;  // compiled once; the main run and every side copy it
  std::unique_ptr<ClosedLoop> loop_;  // the main run's
  int thesis_case_ = 0;
  std::unique_ptr<output::OutputSet> set_;
  std::unique_ptr<runtime::TraceWriter> trace_;
  SideLabel first_label_;
  std::vector<Claim> window_claims_;
  std::vector<Side> sides_;
  CaseResult result_;
  std::string views_, history_;
  std::atomic<int> remaining_{1};
  std::atomic<bool> failed_{false};
  std::mutex mutex_;  // guards what the runs add: warnings, the first error
  std::array<std::int64_t, mjNWARNING> warning_counts_{};
  MujocoWarningTally messages_;
  std::exception_ptr error_;
};

}  // namespace

CaseResult run_case(const std::string& name, const std::string& scene,
                    const std::vector<std::string>& overrides,
                    const std::string& out_dir, const std::string& model_file,
                    const runtime::StopFn& should_stop,
                    const CaseRunOptions& options) {
  const std::unique_ptr<CaseWork> work =
      CaseWork::load(name, scene, overrides, out_dir, model_file, options);
  for (std::size_t i = 0; i < work->runs(); ++i) work->run(i, should_stop);
  return work->finish(should_stop);
}

void run_cases(std::vector<CaseJob>* jobs,
               const std::vector<std::string>& overrides,
               const std::string& out_dir, int threads,
               const std::string& model_file,
               const output::ProgressFn& progress, const runtime::StopFn& stop,
               const CaseRunOptions& options) {
  const int n_threads = threads > 0 ? threads : output::core_count();
  const auto record = [](CaseJob* job, const auto& body) {
    try {
      body();
    } catch (const runtime::Interrupted& e) {
      job->error = e.what();
      job->interrupted = true;
    } catch (const SimError& e) {
      job->error = e.what();
      job->bad_input = true;
    } catch (const std::exception& e) {
      job->error = e.what();
    }
  };
  // each case loaded and checked (bad input ends that case here)
  std::vector<std::unique_ptr<CaseWork>> work(jobs->size());
  output::parallel_for(jobs->size(), n_threads, [&](std::size_t i) {
    CaseJob& job = (*jobs)[i];
    record(&job, [&] {
      work[i] = CaseWork::load(job.name, job.scene, overrides, out_dir,
                               model_file, options);
    });
  });
  // every run of every case in one pool, the main runs (the longest) first;
  // a case is finished by the thread that ends its last run
  std::vector<std::pair<std::size_t, std::size_t>> runs;  // (case, run)
  for (std::size_t c = 0; c < work.size(); ++c) {
    if (work[c]) runs.emplace_back(c, 0);
  }
  for (std::size_t c = 0; c < work.size(); ++c) {
    if (!work[c]) continue;
    for (std::size_t r = 1; r < work[c]->runs(); ++r) runs.emplace_back(c, r);
  }
  std::atomic<std::size_t> finished{0};
  for (const auto& w : work) {
    if (!w && progress) progress(++finished, jobs->size());
  }
  output::parallel_for(runs.size(), n_threads, [&](std::size_t k) {
    const std::size_t c = runs[k].first;
    const auto r = runs[k].second;
    if (!work[c]->run(r, stop)) return;
    CaseJob& job = (*jobs)[c];
    record(&job, [&] { job.result = work[c]->finish(stop); });
    work[c].reset();  // its models, data and set (removed if not committed)
    if (progress) progress(++finished, jobs->size());
  });
}

}  // namespace vmh::thesis
