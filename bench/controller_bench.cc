// Timing of one servo tick: vmh::Controller::tick for each mechanism,
// placement method and error formulation, next to the Appendix D baseline
// (bench/appendix_d_baseline.h: the thesis's float, generic-matrix-routine
// computation of the same f_motion) for the circle and the sphere.
//
// Every benchmark walks a fixed set of kSamples joint configurations drawn
// once from a fixed seed inside the Omni's joint ranges, one configuration
// per iteration; items/s is ticks per second. Consecutive configurations are
// unrelated, so the controller's warm start helps less than in a servo loop
// (the closed-form seed is used whenever it is better, see controller.cc).
//
// Gains are the thesis's case 2/6: K_pos = 0.5 N/mm, K_ornt = 0.5 x 2 pi L
// with L = 50 mm. The surface uses placement weights W = (1, ..., 1).
//
// Before timing, main() checks that the baseline and the controller agree on
// f_motion rows 0-2 (the device force) for every sample, for the circle and
// the sphere with either placement; if they do not, the comparison would be
// between different computations, so the program stops with a message.
#include <benchmark/benchmark.h>

#include "bench/over_samples.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench/appendix_d_baseline.h"
#include "controller/controller.h"
#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh {
namespace {

// a power of two so the wrap-around is a mask
constexpr std::size_t kSamples = 1024;
constexpr std::uint64_t kSeed = 0xc0a7601ULL;

constexpr double kKpos_N_per_mm = 0.5;
constexpr double kLength_mm = 50.0;
constexpr double kOrientationMultiple = 0.5;  // case 2 / case 6

// agreement of the baseline with the controller: |df| <= kRelTol x scale,
// scale = max(|f_controller|, kForceFloor_N), rows 0-2. The floor keeps a
// nearly cancelled force (where float rounding of the 6 x 6 projector
// dominates) from failing on relative error alone.
constexpr double kRelTol = 1e-3;
constexpr double kForceFloor_N = 0.1;

struct Sample {
  Joints q;                        // DH joint angles inside the ranges
  appendix_d::DeviceState device;  // what OpenHaptics would report
};

// built once, on first use, outside any timed region
const std::vector<Sample>& samples() {
  static const std::vector<Sample> set = [] {
    const OmniParams params;
    std::mt19937_64 rng(kSeed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Sample> out(kSamples);
    for (Sample& s : out) {
      for (int i = 0; i < kOmniJoints; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const double lo = params.joint_lower_rad[k];
        const double hi = params.joint_upper_rad[k];
        s.q[i] = lo + (hi - lo) * unit(rng);
      }
      s.device = appendix_d::device_state_from_joints(params, s.q);
    }
    return out;
  }();
  return set;
}

// cycles through the fixed sample set, one call of f per iteration
template <typename F>
void over_samples(benchmark::State& state, F f) {
  static_assert((kSamples & (kSamples - 1)) == 0, "power of two");
  bench::over_samples(state, samples(), f);
}

// A closed, smooth path through the joint ranges, one configuration per
// servo period (1 ms): each joint swings about the middle of its range by
// 30% of the range, a whole number of times per 1024 samples, so the cycle
// closes without a jump. Consecutive configurations are 1 ms apart, as in a
// servo loop, so the controller's warm start is what it would be on the
// device (the joints move at up to about 4 rad/s).
const std::vector<Joints>& trajectory() {
  static const std::vector<Joints> set = [] {
    const OmniParams params;
    constexpr double kTwoPi = 6.283185307179586;
    const int turns[kOmniJoints] = {1, 1, 2, 1, 2, 1};
    const double phase[kOmniJoints] = {0.0, 1.0, 2.0, 0.5, 1.5, 2.5};
    std::vector<Joints> out(kSamples);
    for (std::size_t k = 0; k < kSamples; ++k) {
      for (int i = 0; i < kOmniJoints; ++i) {
        const auto j = static_cast<std::size_t>(i);
        const double lo = params.joint_lower_rad[j];
        const double hi = params.joint_upper_rad[j];
        const double t = static_cast<double>(k) / static_cast<double>(kSamples);
        out[k][i] = 0.5 * (lo + hi) +
                    0.3 * (hi - lo) * std::sin(kTwoPi * turns[i] * t + phase[i]);
      }
    }
    return out;
  }();
  return set;
}

ControllerParams make_params(VmKind kind, PlacementMethod placement,
                             ErrorFormulation error) {
  ControllerParams p;
  p.vm.kind = kind;
  p.vm.length_mm = kLength_mm;
  p.gains.k_pos_N_per_mm = kKpos_N_per_mm;
  p.gains.k_ornt_Nmm_per_rad =
      thesis_orientation_gain(kOrientationMultiple, kLength_mm);
  p.placement = placement;
  p.error = error;
  if (kind == VmKind::kSurface) p.placement_options.weights = Vec6::Ones();
  return p;
}

appendix_d::Settings baseline_settings() {
  return appendix_d::make_settings(static_cast<float>(kKpos_N_per_mm),
                                   static_cast<float>(kLength_mm));
}

// ------------------------------------------------------------- benchmarks

void BM_controller_tick(benchmark::State& state, VmKind kind,
                        PlacementMethod placement, ErrorFormulation error) {
  Controller controller(make_params(kind, placement, error));
  ControlOutput out;
  over_samples(state, [&](const Sample& s) {
    ControlStatus st = controller.tick(s.q, &out);
    benchmark::DoNotOptimize(st);
    benchmark::DoNotOptimize(out);
  });
}

// A closed path along which the stylus follows the VM, as it does while the
// user holds it against the VM (the servo's real use): the wrist centre
// circles once per 1024 samples (1 ms each) on the VM's path in the device
// frame, pressed 2 mm past it (the circle and the sphere of radius L about
// the origin, the surface's handle plane at L above it) with a 1 mm wobble,
// and the gimbal swings by up to 0.3 rad about zero, where the stylus axis
// is the device z axis (the surface's normal). q1..q3 come from the IK
// (nearest the previous sample), outside any timed region.
const std::vector<Joints>& on_path(VmKind kind) {
  static std::vector<Joints> sets[4];
  std::vector<Joints>& set = sets[static_cast<int>(kind)];
  if (!set.empty()) return set;
  const OmniParams params;
  constexpr double kTwoPi = 6.283185307179586;
  set.resize(kSamples);
  Joints near = Joints::Zero();
  for (std::size_t k = 0; k < kSamples; ++k) {
    const double a = kTwoPi * static_cast<double>(k) / kSamples;
    const double wobble_mm = std::sin(7.0 * a);
    Vec3 p_mm;
    switch (kind) {
      case VmKind::kCircle: {
        const double r = kLength_mm + 2.0 + wobble_mm;
        p_mm = Vec3(r * std::cos(a), r * std::sin(a), wobble_mm);
        break;
      }
      case VmKind::kSphere: {
        // a tilted great-circle-like loop on the sphere, in front of the
        // pivot (toward the user)
        const double r = kLength_mm - 2.0 + wobble_mm;
        const Vec3 d(0.6 * std::cos(a), 0.6 * std::sin(a), 0.8);
        p_mm = r * d;
        break;
      }
      case VmKind::kSurface: {
        p_mm = Vec3(30.0 * std::cos(a), 30.0 * std::sin(a),
                    kLength_mm - 2.0 + wobble_mm);
        break;
      }
      case VmKind::kLine: {
        // back and forth along the line (the device y axis), 2 mm off it
        p_mm = Vec3(2.0 + wobble_mm, 40.0 * std::sin(a), wobble_mm);
        break;
      }
    }
    const IkSolutions ik =
        omni_ik_position(params, device_mm_to_base(params, p_mm), near);
    const int best = omni_ik_nearest(ik, near);
    if (best < 0) {
      std::fprintf(stderr, "controller_bench: on_path sample %zu unreachable\n",
                   k);
      std::abort();
    }
    Joints q = ik.q_dh[static_cast<std::size_t>(best)];
    q[3] = 0.3 * std::sin(2.0 * a);
    q[4] = 0.2 * std::sin(3.0 * a + 1.0);
    q[5] = 0.3 * std::sin(a + 2.0);
    set[k] = q;
    near = q;
  }
  return set;
}

// the same tick along trajectory(): the warm start of a servo loop
void BM_controller_tick_trajectory(benchmark::State& state, VmKind kind,
                                   PlacementMethod placement,
                                   ErrorFormulation error) {
  Controller controller(make_params(kind, placement, error));
  ControlOutput out;
  bench::over_samples(state, trajectory(), [&](const Joints& q) {
    ControlStatus st = controller.tick(q, &out);
    benchmark::DoNotOptimize(st);
    benchmark::DoNotOptimize(out);
  });
}

// the same tick along on_path(kind): the stylus following the VM
void BM_controller_tick_on_path(benchmark::State& state, VmKind kind,
                                PlacementMethod placement,
                                ErrorFormulation error) {
  Controller controller(make_params(kind, placement, error));
  ControlOutput out;
  const std::vector<Joints>& path = on_path(kind);
  // one lap first, so that the timed laps start warm
  for (const Joints& q : path) controller.tick(q, &out);
  bench::over_samples(state, path, [&](const Joints& q) {
    ControlStatus st = controller.tick(q, &out);
    benchmark::DoNotOptimize(st);
    benchmark::DoNotOptimize(out);
  });
}

// FK, the Appendix D law and tau = J_r^T F: what a baseline servo tick pays
void BM_appendix_d_tick(benchmark::State& state,
                        appendix_d::Mechanism mechanism) {
  const OmniParams params;
  const appendix_d::Settings settings = baseline_settings();
  appendix_d::TickResult out;
  over_samples(state, [&](const Sample& s) {
    appendix_d::baseline_tick(params, settings, mechanism, s.q, &out);
    benchmark::DoNotOptimize(out);
  });
}

// the Appendix D law alone (listing D.4/D.5 + D.2), from precomputed
// position and stylus axis
void BM_appendix_d_law(benchmark::State& state,
                       appendix_d::Mechanism mechanism) {
  const appendix_d::Settings settings = baseline_settings();
  appendix_d::LawResult out;
  over_samples(state, [&](const Sample& s) {
    if (mechanism == appendix_d::Mechanism::kCircle) {
      appendix_d::circle_law(settings, s.device, &out);
    } else {
      appendix_d::sphere_law(settings, s.device, &out);
    }
    benchmark::DoNotOptimize(out);
  });
}

// the kinematics both ticks share: FK into the device frame, the RM
// Jacobian and tau = J_r^T F for a fixed force
void BM_rm_kinematics(benchmark::State& state) {
  const OmniParams params;
  const Vec3 F_device(0.3, -0.2, 0.1);
  over_samples(state, [&](const Sample& s) {
    const OmniPose pose = omni_fk(params, s.q);
    Vec3 p = base_to_device_mm(params, pose.p_base_m);
    Vec3 axis = base_to_device_vector(pose.R_base.col(2));
    const Mat6 Jr = omni_jacobian(params, s.q);
    Vec3 tau =
        Jr.topLeftCorner<3, 3>().transpose() * device_to_base_vector(F_device);
    benchmark::DoNotOptimize(p);
    benchmark::DoNotOptimize(axis);
    benchmark::DoNotOptimize(tau);
  });
}

void register_benchmarks() {
  std::vector<VmKind> kinds;
  for (const VmDescriptor& d : vm_registry()) kinds.push_back(d.kind);
  const PlacementMethod placements[] = {PlacementMethod::kGaussNewton,
                                        PlacementMethod::kClosedForm};
  auto add_tick = [](VmKind kind, PlacementMethod placement,
                     ErrorFormulation error) {
    const std::string name = std::string("controller_tick/") +
                             vm_kind_name(kind) + "/" +
                             placement_method_name(placement) + "/" +
                             error_formulation_name(error);
    benchmark::RegisterBenchmark(name.c_str(), BM_controller_tick, kind,
                                 placement, error);
  };
  for (VmKind kind : kinds) {
    for (PlacementMethod placement : placements) {
      add_tick(kind, placement, ErrorFormulation::kThesis);
    }
  }
  for (PlacementMethod placement : placements) {
    add_tick(VmKind::kSphere, placement, ErrorFormulation::kGeometric);
  }
  // along a smooth path, warm-started as in a servo loop
  for (VmKind kind : kinds) {
    for (PlacementMethod placement : placements) {
      const std::string name = std::string("controller_tick_trajectory/") +
                               vm_kind_name(kind) + "/" +
                               placement_method_name(placement) + "/thesis";
      benchmark::RegisterBenchmark(name.c_str(), BM_controller_tick_trajectory,
                                   kind, placement, ErrorFormulation::kThesis);
      const std::string on = std::string("controller_tick_on_path/") +
                             vm_kind_name(kind) + "/" +
                             placement_method_name(placement) + "/thesis";
      benchmark::RegisterBenchmark(on.c_str(), BM_controller_tick_on_path,
                                   kind, placement, ErrorFormulation::kThesis);
    }
  }
  benchmark::RegisterBenchmark("appendix_d_tick/circle", BM_appendix_d_tick,
                               appendix_d::Mechanism::kCircle);
  benchmark::RegisterBenchmark("appendix_d_tick/sphere", BM_appendix_d_tick,
                               appendix_d::Mechanism::kSphere);
  benchmark::RegisterBenchmark("appendix_d_law/circle", BM_appendix_d_law,
                               appendix_d::Mechanism::kCircle);
  benchmark::RegisterBenchmark("appendix_d_law/sphere", BM_appendix_d_law,
                               appendix_d::Mechanism::kSphere);
  benchmark::RegisterBenchmark("rm_kinematics", BM_rm_kinematics);
}

// ------------------------------------------------ agreement of the baseline

// statuses under which the controller keeps an old angle or regularises,
// where the stateless baseline cannot be expected to agree
constexpr ControlStatus kIncomparable =
    kStatusInvalidInput | kStatusNumericalFault | kStatusRmAtPivot |
    kStatusOrientationDegenerate | kStatusVmSingular;

// Compares the baseline with Controller::tick over every sample; prints the
// agreement to stderr (stdout may carry JSON) and returns false, after a
// step-by-step account of the worst sample, if they disagree.
bool check_agreement(appendix_d::Mechanism mechanism,
                     PlacementMethod placement) {
  const bool circle = mechanism == appendix_d::Mechanism::kCircle;
  const VmKind kind = circle ? VmKind::kCircle : VmKind::kSphere;
  Controller controller(make_params(kind, placement, ErrorFormulation::kThesis));
  const OmniParams& params = controller.params().omni;
  const appendix_d::Settings settings = baseline_settings();
  const std::vector<Sample>& set = samples();

  double worst_ratio = 0.0, worst_abs = 0.0, worst_rel = 0.0;
  double worst_abs_rot = 0.0, worst_abs_tau = 0.0;
  std::size_t worst = 0, compared = 0, skipped = 0, tau_compared = 0;
  for (std::size_t k = 0; k < set.size(); ++k) {
    ControlOutput out;
    const ControlStatus st = controller.tick(set[k].q, &out);
    if ((st & kIncomparable) != 0) {
      ++skipped;
      continue;
    }
    appendix_d::TickResult base;
    appendix_d::baseline_tick(params, settings, mechanism, set[k].q, &base);
    if (!base.law.inverted) {
      std::fprintf(stderr, "controller_bench: the baseline's inversion "
                           "failed at sample %zu\n", k);
      return false;
    }
    Vec6 fb;
    for (int i = 0; i < 6; ++i) fb[i] = static_cast<double>(base.law.fmotion[i]);
    const double d = (fb.head<3>() - out.f_motion.head<3>()).norm();
    const double fc = out.f_motion.head<3>().norm();
    const double ratio = d / (kRelTol * std::max(fc, kForceFloor_N));
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = k;
    }
    worst_abs = std::max(worst_abs, d);
    if (fc > kForceFloor_N) worst_rel = std::max(worst_rel, d / fc);
    worst_abs_rot =
        std::max(worst_abs_rot, (fb.tail<3>() - out.f_motion.tail<3>()).norm());
    // torques only where the controller did not saturate
    if ((st & (kStatusForceSaturated | kStatusTorqueSaturated)) == 0) {
      worst_abs_tau =
          std::max(worst_abs_tau, (base.tau_dh_Nm - out.tau_dh_Nm).norm());
      ++tau_compared;
    }
    ++compared;
  }
  const char* what = circle ? "circle" : "sphere";
  std::fprintf(stderr,
               "controller_bench: baseline vs controller, %s/%s, %zu samples "
               "(%zu skipped): f_motion rows 0-2 max |df| = %.3g N, max "
               "|df|/|f| = %.3g (|f| > %.2g N), rows 3-5 max |df| = %.3g "
               "N mm, tau max |dtau| = %.3g N m (%zu unsaturated samples)\n",
               what, placement_method_name(placement), compared, skipped,
               worst_abs, worst_rel, kForceFloor_N, worst_abs_rot,
               worst_abs_tau, tau_compared);
  if (compared == 0) {
    std::fprintf(stderr, "controller_bench: no comparable samples\n");
    return false;
  }
  if (worst_ratio <= 1.0) return true;

  // the step-by-step account of the worst sample, from a fresh controller
  // so that the warm start cannot explain it
  Controller fresh(make_params(kind, placement, ErrorFormulation::kThesis));
  ControlOutput out;
  fresh.tick(set[worst].q, &out);
  appendix_d::TickResult base;
  appendix_d::baseline_tick(params, settings, mechanism, set[worst].q, &base);
  const appendix_d::DeviceState& dev = set[worst].device;
  std::fprintf(stderr,
               "controller_bench: FAILED: the Appendix D baseline and "
               "Controller::tick disagree (%s/%s, sample %zu, |df| = %.3g "
               "tolerance units); the benchmark would compare different "
               "computations.\n",
               what, placement_method_name(placement), worst, worst_ratio);
  std::fprintf(stderr, "  status 0x%x\n", static_cast<unsigned>(out.status));
  std::fprintf(stderr, "  p_rm    ctl %.6g %.6g %.6g  base %.6g %.6g %.6g\n",
               out.p_rm_mm[0], out.p_rm_mm[1], out.p_rm_mm[2],
               static_cast<double>(dev.position[0]),
               static_cast<double>(dev.position[1]),
               static_cast<double>(dev.position[2]));
  std::fprintf(stderr, "  axis    ctl %.6g %.6g %.6g  base %.6g %.6g %.6g\n",
               out.axis_rm[0], out.axis_rm[1], out.axis_rm[2],
               static_cast<double>(dev.transform_z[0]),
               static_cast<double>(dev.transform_z[1]),
               static_cast<double>(dev.transform_z[2]));
  const int m = base.law.m;
  for (int j = 0; j < std::min(m, 2); ++j) {
    std::fprintf(stderr, "  theta%d  V ctl %.6g base %.6g  R ctl %.6g base %.6g\n",
                 j + 1, out.theta_v[j], static_cast<double>(base.law.thetaV[j]),
                 out.theta_r[j], static_cast<double>(base.law.thetaR[j]));
  }
  for (int i = 0; i < 6; ++i) {
    std::fprintf(stderr, "  row %d   e ctl %.6g base %.6g  f ctl %.6g base %.6g\n",
                 i, out.e[i], static_cast<double>(base.law.eerror[i]),
                 out.f_motion[i], static_cast<double>(base.law.fmotion[i]));
  }
  return false;
}

bool check_all() {
  bool ok = true;
  for (appendix_d::Mechanism mech :
       {appendix_d::Mechanism::kCircle, appendix_d::Mechanism::kSphere}) {
    for (PlacementMethod placement :
         {PlacementMethod::kGaussNewton, PlacementMethod::kClosedForm}) {
      ok = check_agreement(mech, placement) && ok;
    }
  }
  return ok;
}

}  // namespace
}  // namespace vmh

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!vmh::check_all()) {
    std::fprintf(stderr,
                 "controller_bench: aborting: the baseline check failed\n");
    return 1;
  }
  vmh::register_benchmarks();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
