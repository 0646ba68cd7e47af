#include "thesis/side_runs.h"

#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <set>
#include <string>

namespace vmh::thesis {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)

const char* side_mode_name(SideMode m) {
  return m == SideMode::kFull ? "full" : "fitted";
}

SidePlan plan_side(const HandScript& script, const std::vector<Claim>& claims,
                   bool off_path_only) {
  const std::vector<ScriptSegment>& segs = script.segments();
  SidePlan plan;
  plan.read.assign(segs.size(), 0);
  for (const Claim& c : claims) {
    if (off_path_only && !measured_off_path(c)) continue;
    const std::set<std::string> names = window_segments(c);
    for (std::size_t k = 0; k < segs.size(); ++k) {
      if (names.count(segs[k].name)) plan.read[k] = 1;
    }
  }
  for (std::size_t k = 0; k < segs.size(); ++k) {
    if (plan.read[k]) plan.last_read = static_cast<int>(k);
  }
  return plan;
}

void reserve_rows(std::vector<TickRecord>* rows, std::size_t n) {
  rows->clear();
  if (rows->capacity() >= n) return;
  rows->shrink_to_fit();  // one block at a time
  rows->reserve(n);
#ifdef MADV_HUGEPAGE
  // the whole 2 MB pages inside the block; madvise's failure changes nothing
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(rows->data());
  const std::uintptr_t end = begin + rows->capacity() * sizeof(TickRecord);
  const std::uintptr_t first = (begin + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = end & ~(kHuge - 1);
  if (last > first) {
    madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
  }
#endif
}

void use_reference_gains(ClosedLoop* loop) {
  if (auto ref = reference_params(loop->config().thesis_case,
                                  loop->controller_params())) {
    loop->set_reference(*ref);
  }
}

namespace {

// where the claims start reading segment `s`: the whole sweep, the settled
// half of every other window (thesis/claims.cc)
double read_from_s(const ScriptSegment& s) {
  return s.name == "sweep" ? s.t0_s : s.settled_from_s();
}

// the largest joint speed of the plant (rad/s)
double max_joint_speed(ClosedLoop* loop) {
  const mjModel* m = loop->model();
  const mjData* d = loop->data();
  double v = 0.0;
  for (int i = 0; i < m->nv; ++i) v = std::max(v, std::abs(d->qvel[i]));
  return v;
}

}  // namespace

void run_side(ClosedLoop* loop, const SidePlan& plan, SideMode mode,
              const runtime::StopFn& stop, runtime::TraceWriter* trace,
              SideStats* stats, std::vector<TickRecord>* rows_out) {
  use_reference_gains(loop);
  const auto wall_start = std::chrono::steady_clock::now();
  const HandScript& script = loop->script();
  const std::vector<ScriptSegment>& segs = script.segments();
  const bool fitted = mode == SideMode::kFitted;
  const double end_s = loop->config().sim.duration_s;
  // room for every tick the claims may read (the settled halves of the
  // read segments, the whole sweep), so that the rows are not copied as
  // they grow
  const double T = loop->controller_params().servo_period_s;
  double read_s = 0.0;
  for (std::size_t k = 0; k < segs.size(); ++k) {
    if (!plan.read[k]) continue;
    const ScriptSegment& s = segs[k];
    read_s += s.t1_s - read_from_s(s);
  }
  std::vector<TickRecord>& rows = *rows_out;
  reserve_rows(&rows, static_cast<std::size_t>(read_s / T) + 16);
  TickRecord row;
  SideStats st;
  int segment = -1;
  int calm = 0;         // ticks in a row below the settle speed
  bool settled = false;  // this hold has settled
  int measured = 0;     // settled ticks measured in its settled half
  while (!loop->finished()) {
    if (stop && stop()) throw runtime::Interrupted();
    const int k = script.segment_at(std::min(loop->script_time_s(), end_s));
    if (fitted && k > plan.last_read) break;
    if (k != segment) {
      segment = k;
      calm = 0;
      settled = false;
      measured = 0;
    }
    loop->tick(&row);
    loop->throw_if_physics_fault();
    ++st.ticks;
    if (trace) trace->add(row);
    const ScriptSegment& s = segs[static_cast<std::size_t>(k)];
    const bool read = plan.read[static_cast<std::size_t>(k)] != 0;
    if (read && row.t_s >= read_from_s(s)) rows.push_back(row);
    // only a hold whose target stands still can end early
    if (!fitted || !s.hold || s.name == "sweep" ||
        row.t_s < s.t0_s + script.blend_s()) {
      continue;
    }
    if (!settled) {
      calm = max_joint_speed(loop) < kSettledSpeedRadS ? calm + 1 : 0;
      if (calm < kSettledTicks) continue;
      settled = true;
      ++st.holds_settled;
      // a hold the claims read is measured in its settled half first
      if (read && loop->script_time_s() < s.settled_from_s()) {
        loop->skip_script_to(s.settled_from_s());
      }
    } else if (read && row.t_s >= s.settled_from_s()) {
      ++measured;
    }
    if (!read || measured >= kMeasuredTicks) {
      const double to_s = std::min(s.t1_s, end_s);
      if (to_s > loop->script_time_s()) loop->skip_script_to(to_s);
    }
  }
  st.physics_s = loop->time_s();
  st.script_s = std::min(loop->script_time_s(), end_s);
  st.wall_time_s = std::chrono::duration<double>(
                       std::chrono::steady_clock::now() - wall_start)
                       .count();
  if (stats) *stats = st;
}

}  // namespace vmh::thesis
