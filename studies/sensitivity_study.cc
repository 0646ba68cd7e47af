// The sensitivity study's runs: each point of a planned sweep
// (sensitivity_plan.cc) run as a case with its overrides and Omni edits,
// its claims judged, on worker threads, and the study (the sweep or a
// shard, planned, run and written). The outputs are sensitivity_output.cc,
// the shards' files and their merge sensitivity_shards.cc.
#include "studies/sensitivity_study.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>

#include "output/parallel.h"
#include "sim/cases/case.h"
#include "sim/closed_loop.h"
#include "sim/omni_model_edit.h"
#include "thesis/claims.h"
#include "thesis/run_case.h"

namespace vmh::studies {

PointResult run_point(const SweepPlan& plan, std::size_t index,
                      const runtime::StopFn& stop) {
  PointResult r;
  r.index = index;
  const SweepPoint& pt = plan.points.at(index);
  const SweepCase& c = plan.cases.at(pt.case_index);
  try {
    const double mass = pt.omni_mass_scale, friction = pt.omni_friction_scale;
    const sim::ModelHook hook = [mass, friction](mjModel* m) {
      if (friction != 1.0) {
        for (const char* name : sim::kOmniJoints) {
          const int j = mj_name2id(m, mjOBJ_JOINT, name);
          if (j < 0) throw SimError(std::string("no Omni joint ") + name);
          m->dof_frictionloss[m->jnt_dofadr[j]] *= friction;
        }
      }
      sim::OmniModelEdit edit;
      edit.mass_scale = mass;
      sim::apply_omni_edit(m, edit);
    };
    sim::ClosedLoop loop(c.scene, pt.overrides, hook);
    const int thesis_case = loop.config().thesis_case;
    if (auto ref =
            thesis::reference_params(thesis_case, loop.controller_params())) {
      loop.set_reference(*ref);
    }
    std::vector<TickRecord> rows;
    rows.reserve(static_cast<std::size_t>(loop.ticks_per_run()));
    while (!loop.finished()) {
      runtime::throw_if_stop_asked(stop);
      rows.emplace_back();
      loop.tick(&rows.back());
    }
    r.rms_path_error_mm =
        thesis::run_metrics(rows, loop.the_case()).rms_path_error_mm;
    for (const thesis::Claim& cl :
         thesis::evaluate_claims(thesis_case, rows, loop.the_case())) {
      r.claims.push_back({cl.name, cl.value, cl.threshold, cl.comparison,
                          cl.unit, static_cast<bool>(cl.pass)});
    }
  } catch (const runtime::Interrupted&) {
    throw;  // not the point's failure: the sweep stops
  } catch (const std::exception& e) {
    r.error = e.what();
    r.rms_path_error_mm = std::nan("");
    r.claims.clear();
  }
  return r;
}

std::vector<std::size_t> all_points(const SweepPlan& plan) {
  std::vector<std::size_t> all(plan.points.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return all;
}

std::vector<PointResult> run_points(const SweepPlan& plan,
                                    const std::vector<std::size_t>& which,
                                    int jobs,
                                    const output::ProgressFn& progress,
                                    const runtime::StopFn& stop) {
  const std::vector<std::size_t>& list = which;
  std::vector<PointResult> out(list.size());
  std::atomic<std::size_t> done{0};
  std::atomic<bool> stopped{false};
  output::parallel_for(list.size(), jobs > 0 ? jobs : output::core_count(),
                       [&](std::size_t i) {
                         if (stopped || runtime::stop_asked(stop)) {
                           stopped = true;
                           return;
                         }
                         try {
                           out[i] = run_point(plan, list[i], stop);
                         } catch (const runtime::Interrupted&) {
                           stopped = true;
                           return;
                         }
                         if (progress) progress(++done, list.size());
                       });
  if (stopped) throw runtime::Interrupted();
  return out;
}

SensitivityResult run_sensitivity_study(const SensitivityOptions& o) {
  SensitivityResult r;
  r.plan = plan_sweep(o.sweep);
  r.shard_k = o.shard_k;
  r.shard_n = o.shard_n;
  // a shard past the last point (k > the plan's points) runs none
  const std::vector<std::size_t> which =
      r.is_shard() ? shard_points(r.plan.points.size(), o.shard_k, o.shard_n)
                   : all_points(r.plan);
  // the bar's total before the first point ends
  if (o.progress && !which.empty()) o.progress(0, which.size());
  r.results = run_points(r.plan, which, o.jobs, o.progress, o.should_stop);
  // the last poll: from here the files go in
  runtime::throw_if_stop_asked(o.should_stop);
  if (!o.out_dir.empty()) r.files = write_sensitivity_files(r, o.out_dir);
  return r;
}

double claim_margin(const ClaimOutcome& c) {
  const double m = c.comparison == "<=" ? c.threshold - c.value
                                        : c.value - c.threshold;
  return c.threshold != 0.0 ? m / std::abs(c.threshold) : m;
}

}  // namespace vmh::studies
