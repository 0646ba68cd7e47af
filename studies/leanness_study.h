// "Leave out what a scene does not need", measured (issue 5, item 4): for
// each case, the steps per second of the scene as composed against the same
// scene with what it leaves out switched back on, one ingredient at a time
// and all together:
//   contacts   the contact flag on and every geom colliding (contype =
//              conaffinity = 1, MuJoCo's defaults), as an Omni model with
//              collision geometry on every link would be;
//   gravity    gravity on (0, 0, -9.81 m/s^2);
//   rendering  an mjvScene (mjv_makeScene, 1000 geoms) brought up to date
//              with mjv_updateScene after every servo tick, as a viewer
//              would; CPU side only, no OpenGL context.
// and, the other way, `no_frictionloss`: the composed scene without the
// joints' dry friction, which the scene keeps because the device has it,
// to show what that costs.
//
// The variants change the model after loading (disable flags, gravity,
// geom_contype/conaffinity), so that every other number stays the scene's.
// "Full Omni where one DOF would do" is not a variant: every case scene
// already needs all six joints (the controller reads them, the hand moves
// them), so there is nothing to leave out.
//
// Each variant runs the closed loop over the case's whole script compressed
// into `duration_s` (duration_s is set to it, so every segment is visited).
// Repeats are interleaved across the variants and the fastest repeat of each
// is kept (the machine is shared). The controller's share of a tick is
// measured apart, by running a fresh Controller over the composed run's
// readings, so that the physics' own steps per second can be estimated.
// Timings are reported, never asserted.
#ifndef VMHAPTICS_STUDIES_LEANNESS_STUDY_H_
#define VMHAPTICS_STUDIES_LEANNESS_STUDY_H_

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "runtime/stop.h"

namespace vmh::studies {

// what a variant switches on (or, for kNoFrictionloss, off)
enum Ingredient : unsigned {
  kContacts = 1u << 0,
  kGravity = 1u << 1,
  kRendering = 1u << 2,
  kNoFrictionloss = 1u << 3,
};

struct LeannessVariant {
  std::string name;
  unsigned ingredients = 0;
};

// composed, contacts, gravity, rendering, all (the first three together),
// no_frictionloss
const std::vector<LeannessVariant>& leanness_variants();

struct LeannessOptions {
  // case names (case_catalogue()) or scene paths; name and path each
  std::vector<std::pair<std::string, std::string>> scenes;
  std::vector<std::string> overrides;
  double duration_s = 2.0;  // simulated per variant and repeat
  int repeats = 5;
  std::string out_dir;  // where leanness.csv goes; empty: nothing written
  // polled between the cases' loads, before each variant's run and every
  // 64 of its ticks, and last before leanness.csv is written
  // (runtime/stop.h); not set: never stops
  runtime::StopFn should_stop;
};

struct VariantResult {
  LeannessVariant variant;
  // closed loop (hand, controller, physics), fastest repeat; the thread's
  // CPU time beside the wall time, since other processes share the cores
  double wall_time_s = 0.0;
  double cpu_time_s = 0.0;
  double steps_per_s = 0.0;      // physics steps per wall second
  double cpu_steps_per_s = 0.0;  // per CPU second
  double realtime_factor = 0.0;  // simulated s per wall s
  // this variant's time over the composed scene's (> 1: the variant is
  // slower), by wall and by CPU time; physics_slowdown: by CPU time with the
  // controller's share (CaseLeanness::controller_cpu_time_s) taken out of
  // both
  double slowdown = 1.0;
  double cpu_slowdown = 1.0;
  double physics_slowdown = 1.0;
  // structural facts, read from the model and data the run used
  bool contact_enabled = false;
  int colliding_geoms = 0;     // geoms some other geom's contype/conaffinity meets
  bool gravity_enabled = false;
  bool frictionloss_enabled = false;
  double mean_ncon = 0.0;      // contacts per servo tick (after its steps)
  int max_ncon = 0;
  double mean_nefc = 0.0;      // constraint rows per servo tick
  int max_nefc = 0;
  int scene_geoms = 0;         // mjvScene geoms after the last update (0: off)
  // CPU time of one mjv_updateScene (us; 0 without rendering), timed apart
  // over as many calls as the run has ticks, least over the repeats: the
  // rendering's cost measured directly, finer than the run's noise
  double render_us_per_tick = 0.0;
  // how far the variant's wrist centre went from the composed run's, max
  // over ticks (mm): what the ingredient did to the physics
  double max_deviation_mm = 0.0;
  int mujoco_warnings = 0;
};

struct CaseLeanness {
  std::string name;
  std::string scene;
  int nv = 0;
  int ngeom = 0;
  int substeps = 0;
  double step_s = 0.0;
  int ticks = 0;
  // a fresh Controller over the composed run's readings, least CPU time
  double controller_cpu_time_s = 0.0;
  std::vector<VariantResult> variants;  // in leanness_variants() order
};

struct LeannessResult {
  double duration_s = 0.0;
  int repeats = 0;
  std::vector<CaseLeanness> cases;
  double study_wall_time_s = 0.0;
  std::vector<std::string> files;  // the paths written (out_dir)
};

// Runs the study and, with out_dir, writes its file (write_leanness_files).
// Throws SimError on a bad scene or override, before any run;
// runtime::Interrupted when should_stop says so, before anything is
// written.
LeannessResult run_leanness_study(const LeannessOptions& options);

// one row per case and variant, units in the column names
std::string leanness_csv(const LeannessResult& r);

// What the command line prints: every case's variants, the median CPU
// slowdown of each variant over the cases, and the files written.
nlohmann::ordered_json leanness_json(const LeannessResult& r);

// out_dir/leanness.csv; returns its path
std::vector<std::string> write_leanness_files(const LeannessResult& r,
                                              const std::string& out_dir);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_LEANNESS_STUDY_H_
