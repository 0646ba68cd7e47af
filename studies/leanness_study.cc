#include "studies/leanness_study.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>

#include <time.h>

#include "controller/controller.h"
#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "output/output_file.h"
#include "sim/closed_loop.h"
#include "sim/mujoco_util.h"
#include "studies/study_numbers.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

using detail::exact;
using detail::thread_cpu_s;

using Clock = std::chrono::steady_clock;

// room for every geom of the Omni and the hand many times over; simulate's
// default is 2000 for scenes far larger than these
constexpr int kSceneMaxGeoms = 1000;

// an mjvScene with its option and camera, freed with it
class ViewerState {
 public:
  explicit ViewerState(const mjModel* m) {
    mjv_defaultScene(&scene_);
    mjv_defaultOption(&option_);
    mjv_defaultCamera(&camera_);
    mjv_makeScene(m, &scene_, kSceneMaxGeoms);
  }
  ~ViewerState() { mjv_freeScene(&scene_); }
  ViewerState(const ViewerState&) = delete;
  ViewerState& operator=(const ViewerState&) = delete;

  void update(const mjModel* m, mjData* d) {
    mjv_updateScene(m, d, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  }
  int geoms() const { return scene_.ngeom; }

 private:
  mjvScene scene_;
  mjvOption option_;
  mjvCamera camera_;
};

// One variant's loop, its model changed as the variant says.
struct VariantLoop {
  LeannessVariant variant;
  std::unique_ptr<ClosedLoop> loop;
  std::unique_ptr<ViewerState> viewer;
  VariantResult result;
  std::vector<Vec3> p_mm;       // wrist centre per tick, last repeat
  std::vector<Joints> q_read;   // what the controller read, per tick
};

// MuJoCo 2.2.2's own stack size for these scenes (it sizes it from njmax
// = 500 and nconmax = 100 when <size nstack> is not given)
constexpr int kMujocoDefaultStack = 1281600;

void switch_on(ClosedLoop* loop, unsigned ingredients) {
  // ClosedLoop owns its model non-const (load_model returns an mjModel*)
  // and hands it out read-only; the variants change only option flags,
  // gravity and collision masks, none of which ClosedLoop caches, and then
  // reset the loop so that mjData follows.
  mjModel* m = const_cast<mjModel*>(loop->model());
  if (ingredients & kContacts) {
    m->opt.disableflags &= ~static_cast<int>(mjDSBL_CONTACT);
    for (int g = 0; g < m->ngeom; ++g) {
      m->geom_contype[g] = 1;
      m->geom_conaffinity[g] = 1;
    }
  }
  if (ingredients & kGravity) {
    m->opt.disableflags &= ~static_cast<int>(mjDSBL_GRAVITY);
    m->opt.gravity[0] = 0.0;
    m->opt.gravity[1] = 0.0;
    m->opt.gravity[2] = -9.81;
  }
  if (ingredients & kNoFrictionloss) {
    m->opt.disableflags |= mjDSBL_FRICTIONLOSS;
  }
  loop->reset();
}

void run_variant(VariantLoop* v, int ticks, const runtime::StopFn& stop) {
  ClosedLoop& loop = *v->loop;
  const mjModel* m = loop.model();
  mjData* d = loop.data();
  const OmniParams& omni = loop.controller_params().omni;
  const std::size_t n = static_cast<std::size_t>(ticks);
  v->p_mm.resize(n);
  v->q_read.resize(n);
  long ncon_sum = 0, nefc_sum = 0;
  int ncon_max = 0, nefc_max = 0;

  loop.reset();
  TickRecord row;
  const auto t0 = Clock::now();
  const double cpu0 = thread_cpu_s();
  for (std::size_t k = 0; k < n; ++k) {
    // every 64 ticks: a poll per tick would be timed with the variant
    if ((k & 63u) == 0) runtime::throw_if_stop_asked(stop);
    loop.tick(&row);
    if (v->viewer) v->viewer->update(m, d);
    v->p_mm[k] =
        base_to_device_mm(omni, omni_fk(omni, loop.device().true_q_dh()).p_base_m);
    v->q_read[k] = row.q_dh;
    ncon_sum += d->ncon;
    nefc_sum += d->nefc;
    ncon_max = std::max(ncon_max, d->ncon);
    nefc_max = std::max(nefc_max, d->nefc);
  }
  const double cpu_s = thread_cpu_s() - cpu0;
  const double wall_s = std::chrono::duration<double>(Clock::now() - t0).count();

  VariantResult& r = v->result;
  r.wall_time_s = std::min(r.wall_time_s, wall_s);
  r.cpu_time_s = std::min(r.cpu_time_s, cpu_s);
  const double nn = std::max<double>(1.0, static_cast<double>(n));
  r.mean_ncon = static_cast<double>(ncon_sum) / nn;
  r.max_ncon = ncon_max;
  r.mean_nefc = static_cast<double>(nefc_sum) / nn;
  r.max_nefc = nefc_max;
  r.scene_geoms = v->viewer ? v->viewer->geoms() : 0;
  if (v->viewer) {
    // the update alone, as many times as the run had ticks, from where the
    // run ended (clocking each call inside the run would cost as much as
    // the call)
    const double c0 = thread_cpu_s();
    for (std::size_t k = 0; k < n; ++k) v->viewer->update(m, d);
    const double us = 1e6 * (thread_cpu_s() - c0) / nn;
    r.render_us_per_tick =
        r.render_us_per_tick > 0.0 ? std::min(r.render_us_per_tick, us) : us;
  }
  int warnings = 0;
  for (int i = 0; i < mjNWARNING; ++i) warnings += d->warning[i].number;
  r.mujoco_warnings = warnings;
}

}  // namespace

const std::vector<LeannessVariant>& leanness_variants() {
  static const std::vector<LeannessVariant> variants = {
      {"composed", 0u},
      {"contacts", kContacts},
      {"gravity", kGravity},
      {"rendering", kRendering},
      {"all", kContacts | kGravity | kRendering},
      {"no_frictionloss", kNoFrictionloss},
  };
  return variants;
}

namespace {

// A case's loops, one per variant in leanness_variants() order, each with
// the variant's ingredients switched on.
std::vector<VariantLoop> make_loops(const std::string& scene,
                                    const std::vector<std::string>& sets) {
  std::vector<VariantLoop> loops;
  for (const LeannessVariant& variant : leanness_variants()) {
    VariantLoop v;
    v.variant = variant;
    v.result.variant = variant;
    v.result.wall_time_s = std::numeric_limits<double>::infinity();
    v.result.cpu_time_s = std::numeric_limits<double>::infinity();
    // The case scenes size mjData for their few constraint rows (<size
    // njmax nconmax nstack>, models/cases/README.md), with room for the
    // 26 rows and 5 contacts this variant has been seen to make; its stack
    // is raised to MuJoCo's own default, 1.28 million mjtNums, so that the
    // solver's scratch never runs out whatever the contacts. The stack is
    // allocated by mj_makeData from m->nstack, so it may be raised after
    // compiling (nothing else is sized from it); njmax and nconmax may not.
    ModelHook hook;
    if (variant.ingredients & kContacts) {
      hook = [](mjModel* m) { m->nstack = std::max(m->nstack, kMujocoDefaultStack); };
    }
    v.loop = std::make_unique<ClosedLoop>(scene, sets, hook);
    switch_on(v.loop.get(), variant.ingredients);
    if (variant.ingredients & kRendering) {
      v.viewer = std::make_unique<ViewerState>(v.loop->model());
    }
    loops.push_back(std::move(v));
  }
  return loops;
}

// the controller alone over the composed run's readings, least CPU time
double controller_cpu_s(const VariantLoop& composed, int repeats) {
  double controller_s = std::numeric_limits<double>::infinity();
  for (int rep = 0; rep < repeats; ++rep) {
    Controller controller(composed.loop->controller_params());
    ControlOutput out;
    const double cpu0 = thread_cpu_s();
    for (const Joints& q : composed.q_read) controller.tick(q, &out);
    controller_s = std::min(controller_s, thread_cpu_s() - cpu0);
  }
  return controller_s;
}

// A variant's rates and slowdowns against the composed scene's, what its
// model switched on, and how far it moved from the composed run.
VariantResult variant_result(const VariantLoop& v, const VariantLoop& composed,
                             const CaseLeanness& cl) {
  const double steps = static_cast<double>(cl.ticks) * cl.substeps;
  const double simulated_s = cl.ticks * composed.loop->controller_params().servo_period_s;
  const double composed_s = composed.result.wall_time_s;
  const double composed_cpu_s = composed.result.cpu_time_s;
  const double controller_s = cl.controller_cpu_time_s;
  VariantResult r = v.result;
  const mjModel* m = v.loop->model();
  r.steps_per_s = steps / r.wall_time_s;
  r.cpu_steps_per_s = steps / r.cpu_time_s;
  r.realtime_factor = simulated_s / r.wall_time_s;
  r.slowdown = r.wall_time_s / composed_s;
  r.cpu_slowdown = r.cpu_time_s / composed_cpu_s;
  r.physics_slowdown = (r.cpu_time_s - controller_s) /
                       std::max(composed_cpu_s - controller_s, 1e-12);
  r.contact_enabled = !(m->opt.disableflags & mjDSBL_CONTACT);
  r.gravity_enabled = !(m->opt.disableflags & mjDSBL_GRAVITY) &&
                      (m->opt.gravity[0] != 0.0 || m->opt.gravity[1] != 0.0 ||
                       m->opt.gravity[2] != 0.0);
  r.frictionloss_enabled = !(m->opt.disableflags & mjDSBL_FRICTIONLOSS);
  // a geom can collide when some other geom's bits meet its own
  // (contype of one & conaffinity of the other, either way); the Omni's
  // collision class has contype 1 and conaffinity 0 everywhere, so no pair
  r.colliding_geoms = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    for (int h = 0; h < m->ngeom; ++h) {
      if (h != g && ((m->geom_contype[g] & m->geom_conaffinity[h]) != 0 ||
                     (m->geom_contype[h] & m->geom_conaffinity[g]) != 0)) {
        ++r.colliding_geoms;
        break;
      }
    }
  }
  r.max_deviation_mm = 0.0;
  for (std::size_t k = 0; k < v.p_mm.size(); ++k) {
    r.max_deviation_mm =
        std::max(r.max_deviation_mm, (v.p_mm[k] - composed.p_mm[k]).norm());
  }
  return r;
}

// One case: its variants run `repeats` times, interleaved.
CaseLeanness measure_case(const std::pair<std::string, std::string>& scene,
                          std::vector<VariantLoop>* loops_in, int repeats,
                          const runtime::StopFn& stop) {
  std::vector<VariantLoop>& loops = *loops_in;
  const ClosedLoop& first = *loops.front().loop;
  CaseLeanness cl;
  cl.name = scene.first;
  cl.scene = scene.second;
  cl.nv = first.model()->nv;
  cl.ngeom = first.model()->ngeom;
  cl.substeps = first.substeps();
  cl.step_s = first.model()->opt.timestep;
  // at most sim::kMaxTicksPerRun (1e9), which an int holds
  cl.ticks = static_cast<int>(first.ticks_per_run());

  // each repeat starts one variant further on, so that no variant always
  // runs first (cold caches) or right after the same neighbour
  for (int rep = 0; rep < repeats; ++rep) {
    for (std::size_t i = 0; i < loops.size(); ++i) {
      run_variant(&loops[(i + static_cast<std::size_t>(rep)) % loops.size()],
                  cl.ticks, stop);
    }
  }
  cl.controller_cpu_time_s = controller_cpu_s(loops.front(), repeats);
  for (const VariantLoop& v : loops) {
    cl.variants.push_back(variant_result(v, loops.front(), cl));
  }
  return cl;
}

}  // namespace

LeannessResult run_leanness_study(const LeannessOptions& o) {
  const auto study_start = Clock::now();
  LeannessResult result;
  result.duration_s = o.duration_s;
  result.repeats = std::max(1, o.repeats);
  if (!(o.duration_s > 0.0)) throw SimError("the duration must be > 0");

  std::vector<std::string> sets = o.overrides;
  sets.push_back("duration_s=" + exact(o.duration_s));
  // every loop is built (and every scene checked) before the first run
  std::vector<std::vector<VariantLoop>> all;
  for (const auto& scene : o.scenes) {
    runtime::throw_if_stop_asked(o.should_stop);
    all.push_back(make_loops(scene.second, sets));
  }
  for (std::size_t c = 0; c < o.scenes.size(); ++c) {
    result.cases.push_back(
        measure_case(o.scenes[c], &all[c], result.repeats, o.should_stop));
  }
  result.study_wall_time_s =
      std::chrono::duration<double>(Clock::now() - study_start).count();
  // the last poll: from here leanness.csv goes in
  runtime::throw_if_stop_asked(o.should_stop);
  if (!o.out_dir.empty()) {
    result.files = write_leanness_files(result, o.out_dir);
  }
  return result;
}

std::string leanness_csv(const LeannessResult& r) {
  std::string s =
      "case,variant,contacts,gravity,rendering,frictionloss,wall_time_s,"
      "cpu_time_s,steps_per_s,cpu_steps_per_s,realtime_factor,slowdown,"
      "cpu_slowdown,physics_slowdown,controller_cpu_time_s,mean_ncon,max_ncon,"
      "mean_nefc,max_nefc,colliding_geoms,scene_geoms,render_us_per_tick,"
      "max_deviation_mm,mujoco_warnings\n";
  char buf[512];
  for (const CaseLeanness& c : r.cases) {
    for (const VariantResult& v : c.variants) {
      std::snprintf(buf, sizeof buf,
                    "%s,%s,%d,%d,%d,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,"
                    "%.6g,%.9g,%.6g,%d,%.6g,%d,%d,%d,%.6g,%.9g,%d\n",
                    c.name.c_str(), v.variant.name.c_str(),
                    v.contact_enabled ? 1 : 0, v.gravity_enabled ? 1 : 0,
                    (v.variant.ingredients & kRendering) ? 1 : 0,
                    v.frictionloss_enabled ? 1 : 0, v.wall_time_s,
                    v.cpu_time_s, v.steps_per_s, v.cpu_steps_per_s,
                    v.realtime_factor, v.slowdown, v.cpu_slowdown,
                    v.physics_slowdown, c.controller_cpu_time_s, v.mean_ncon,
                    v.max_ncon, v.mean_nefc, v.max_nefc, v.colliding_geoms,
                    v.scene_geoms, v.render_us_per_tick, v.max_deviation_mm,
                    v.mujoco_warnings);
      s += buf;
    }
  }
  return s;
}

namespace {

using Json = nlohmann::ordered_json;

Json ingredient_names(unsigned ingredients) {
  Json names = Json::array();
  if (ingredients & kContacts) names.push_back("contacts");
  if (ingredients & kGravity) names.push_back("gravity");
  if (ingredients & kRendering) names.push_back("rendering");
  if (ingredients & kNoFrictionloss) names.push_back("no_frictionloss");
  return names;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Json variant_json(const VariantResult& v) {
  return {
      {"variant", v.variant.name},
      {"ingredients", ingredient_names(v.variant.ingredients)},
      {"wall_time_s", v.wall_time_s},
      {"cpu_time_s", v.cpu_time_s},
      {"steps_per_s", v.steps_per_s},
      {"cpu_steps_per_s", v.cpu_steps_per_s},
      {"realtime_factor", v.realtime_factor},
      {"slowdown", v.slowdown},
      {"cpu_slowdown", v.cpu_slowdown},
      {"physics_slowdown", v.physics_slowdown},
      {"contact_enabled", v.contact_enabled},
      {"colliding_geoms", v.colliding_geoms},
      {"gravity_enabled", v.gravity_enabled},
      {"frictionloss_enabled", v.frictionloss_enabled},
      {"mean_ncon", v.mean_ncon},
      {"max_ncon", v.max_ncon},
      {"mean_nefc", v.mean_nefc},
      {"max_nefc", v.max_nefc},
      {"scene_geoms", v.scene_geoms},
      {"render_us_per_tick", v.render_us_per_tick},
      {"max_deviation_mm", v.max_deviation_mm},
      {"mujoco_warnings", v.mujoco_warnings},
  };
}

}  // namespace

nlohmann::ordered_json leanness_json(const LeannessResult& r) {
  Json cases = Json::array();
  std::vector<std::vector<double>> slowdowns(leanness_variants().size());
  for (const CaseLeanness& c : r.cases) {
    Json variants = Json::array();
    for (std::size_t i = 0; i < c.variants.size(); ++i) {
      slowdowns[i].push_back(c.variants[i].cpu_slowdown);
      variants.push_back(variant_json(c.variants[i]));
    }
    cases.push_back({{"case", c.name},
                     {"scene", c.scene},
                     {"nv", c.nv},
                     {"ngeom", c.ngeom},
                     {"h_s", c.step_s},
                     {"substeps_per_tick", c.substeps},
                     {"ticks", c.ticks},
                     {"controller_cpu_time_s", c.controller_cpu_time_s},
                     {"variants", variants}});
  }
  Json summary = Json::object();
  for (std::size_t i = 0; i < leanness_variants().size(); ++i) {
    summary[leanness_variants()[i].name] = {
        {"median_cpu_slowdown", median(slowdowns[i])}};
  }
  Json j = {
      {"study", "leanness"},
      {"duration_s", r.duration_s},
      {"script", "each case's whole script, compressed into duration_s"},
      {"repeats", r.repeats},
      {"not_measured",
       {{"full_omni",
         "every case scene already holds the full Omni (nv = 6): the "
         "controller reads all six joints and the hand moves them, so no "
         "lighter model would run the same case"}}},
      {"median_over_cases", summary},
      {"cases", cases},
      {"study_wall_time_s", r.study_wall_time_s},
  };
  if (!r.files.empty()) j["files"] = r.files;
  return j;
}

std::vector<std::string> write_leanness_files(const LeannessResult& r,
                                              const std::string& out_dir) {
  return {output::write_file_in(out_dir, "leanness.csv", leanness_csv(r))};
}

}  // namespace vmh::studies
