// Timing of the Omni kinematics (controller/omni_kinematics.h).
//
// Every benchmark walks a fixed set of kSamples configurations drawn once from
// a fixed seed, so the branches taken do not depend on the iteration count and
// runs are comparable. One iteration is one call; items/s is calls per second.
#include <benchmark/benchmark.h>

#include "bench/over_samples.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh {
namespace {

// a power of two so the wrap-around is a mask
constexpr std::size_t kSamples = 1024;
constexpr std::uint64_t kSeed = 0x5eed0d17ULL;
// the ik hint is the true solution nudged by up to this much (rad), as in a
// servo loop that seeds with the previous tick's angles
constexpr double kHintNoiseRad = 0.05;

struct Sample {
  Joints q;     // joint angles inside the OmniParams ranges
  Joints near;  // ik hint: q plus a little noise
  OmniPose pose;
  IkSolutions pose_solutions;  // omni_ik_pose output, for omni_ik_nearest
};

// built once, on first use, outside any timed region
const std::vector<Sample>& samples() {
  static const std::vector<Sample> set = [] {
    const OmniParams params;
    std::mt19937_64 rng(kSeed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_real_distribution<double> noise(-kHintNoiseRad, kHintNoiseRad);
    std::vector<Sample> out(kSamples);
    for (Sample& s : out) {
      for (int i = 0; i < kOmniJoints; ++i) {
        const double lo = params.joint_lower_rad[i];
        const double hi = params.joint_upper_rad[i];
        s.q[i] = lo + (hi - lo) * unit(rng);
        s.near[i] = s.q[i] + noise(rng);
      }
      s.pose = omni_fk(params, s.q);
      s.pose_solutions =
          omni_ik_pose(params, s.pose.p_base_m, s.pose.R_base, s.near);
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

void BM_omni_fk(benchmark::State& state) {
  const OmniParams params;
  over_samples(state, [&](const Sample& s) {
    OmniPose pose = omni_fk(params, s.q);
    benchmark::DoNotOptimize(pose);
  });
}
BENCHMARK(BM_omni_fk);

void BM_omni_jacobian(benchmark::State& state) {
  const OmniParams params;
  over_samples(state, [&](const Sample& s) {
    Mat6 J = omni_jacobian(params, s.q);
    benchmark::DoNotOptimize(J);
  });
}
BENCHMARK(BM_omni_jacobian);

void BM_omni_ik_position(benchmark::State& state) {
  const OmniParams params;
  over_samples(state, [&](const Sample& s) {
    IkSolutions sol = omni_ik_position(params, s.pose.p_base_m, s.near);
    benchmark::DoNotOptimize(sol);
  });
}
BENCHMARK(BM_omni_ik_position);

void BM_omni_ik_pose(benchmark::State& state) {
  const OmniParams params;
  over_samples(state, [&](const Sample& s) {
    IkSolutions sol =
        omni_ik_pose(params, s.pose.p_base_m, s.pose.R_base, s.near);
    benchmark::DoNotOptimize(sol);
  });
}
BENCHMARK(BM_omni_ik_pose);

// the selection step alone, over precomputed pose solutions
void BM_omni_ik_nearest(benchmark::State& state) {
  over_samples(state, [&](const Sample& s) {
    int best = omni_ik_nearest(s.pose_solutions, s.near);
    benchmark::DoNotOptimize(best);
  });
}
BENCHMARK(BM_omni_ik_nearest);

// what a servo tick pays: solve the pose, then keep the nearest branch
void BM_omni_ik_pose_nearest(benchmark::State& state) {
  const OmniParams params;
  over_samples(state, [&](const Sample& s) {
    const IkSolutions sol =
        omni_ik_pose(params, s.pose.p_base_m, s.pose.R_base, s.near);
    int best = omni_ik_nearest(sol, s.near);
    benchmark::DoNotOptimize(best);
  });
}
BENCHMARK(BM_omni_ik_pose_nearest);

}  // namespace
}  // namespace vmh
