// The Omni's forward kinematics and Jacobian next to two outside anchors on
// the same chain (issue 18):
//   kinematics/omni_fk_jacobian     vmh::omni_fk_jacobian: pose and the 6 x 6
//                                   Jacobian in one pass
//   kinematics/omni_fk_then_jacobian  omni_fk, then omni_jacobian: the chain
//                                   of 4 x 4 products twice (the servo tick
//                                   before issue 18)
//   kinematics/kdl_fk_jacobian      KDL's ChainFkSolverPos_recursive and
//                                   ChainJntToJacSolver on Table B.1 (built
//                                   where liborocos-kdl-dev is found)
//   kinematics/mujoco_fk_jacobian   mj_kinematics, mj_comPos and mj_jacSite
//                                   on models/omni/omni.xml's "wrist" site
//                                   (built with the testbed)
// Each iteration is one configuration of a fixed set of 1024 drawn from a
// fixed seed inside the joint ranges; each computes the wrist centre, the
// stylus rotation and the 6 x 6 Jacobian at the wrist centre.
//
// Before timing, main() checks that every anchor gives the same pose and
// Jacobian as omni_fk / omni_jacobian on every sample (within 1e-9; observed
// about 1e-15): otherwise the comparison would be between different
// computations, and the program stops with a message.
#include <benchmark/benchmark.h>

#include "bench/over_samples.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "controller/types.h"

#ifdef VMH_HAVE_KDL
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#endif

#ifdef VMH_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace vmh {
namespace {

constexpr std::size_t kSamples = 1024;
constexpr std::uint64_t kSeed = 0xa2c40125ULL;
constexpr double kAgree = 1e-9;

struct Result {
  Vec3 p = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  Mat6 J = Mat6::Zero();
};

const std::vector<Joints>& samples() {
  static const std::vector<Joints> set = [] {
    const OmniParams params;
    std::mt19937_64 rng(kSeed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Joints> out(kSamples);
    for (Joints& q : out) {
      for (int i = 0; i < kOmniJoints; ++i) {
        const auto k = static_cast<std::size_t>(i);
        q[i] = params.joint_lower_rad[k] +
               (params.joint_upper_rad[k] - params.joint_lower_rad[k]) *
                   unit(rng);
      }
    }
    return out;
  }();
  return set;
}

template <typename F>
void over_samples(benchmark::State& state, F f) {
  bench::over_samples(state, samples(), f);
}

// -------------------------------------------------------------- the project

void omni_one_pass(const OmniParams& p, const Joints& q, Result* r) {
  OmniPose pose;
  omni_fk_jacobian(p, q, &pose, &r->J);
  r->p = pose.p_base_m;
  r->R = pose.R_base;
}

void omni_chain_twice(const OmniParams& p, const Joints& q, Result* r) {
  const OmniPose pose = omni_fk(p, q);
  r->p = pose.p_base_m;
  r->R = pose.R_base;
  r->J = omni_jacobian(p, q);
}

void BM_omni_fk_jacobian(benchmark::State& state) {
  const OmniParams params;
  Result r;
  over_samples(state, [&](const Joints& q) {
    omni_one_pass(params, q, &r);
    benchmark::DoNotOptimize(r);
  });
}

void BM_omni_fk_then_jacobian(benchmark::State& state) {
  const OmniParams params;
  Result r;
  over_samples(state, [&](const Joints& q) {
    omni_chain_twice(params, q, &r);
    benchmark::DoNotOptimize(r);
  });
}

// --------------------------------------------------------------------- KDL

#ifdef VMH_HAVE_KDL
// Table B.1 as a KDL chain. Modified DH puts the joint between
// RotX(alpha_{i-1}) TransX(a_{i-1}) and TransZ(d_i); a KDL segment turns its
// joint at its root, so segment i is joint i (with its theta offset), then
// TransZ(d_i), then the next row's RotX(alpha_i) TransX(a_i). KDL applies
// the Jacobian at the chain's tip (the wrist centre) in base-frame
// coordinates, rows (v, w): the layout of omni_jacobian.
KDL::Chain omni_kdl_chain(const OmniParams& p) {
  const std::array<DhRow, kOmniJoints> table = omni_dh_table(p);
  KDL::Chain chain;
  for (int i = 0; i < kOmniJoints; ++i) {
    const DhRow& row = table[static_cast<std::size_t>(i)];
    KDL::Frame tip(KDL::Vector(0.0, 0.0, row.d_m));
    if (i + 1 < kOmniJoints) {
      const DhRow& next = table[static_cast<std::size_t>(i + 1)];
      tip = tip * KDL::Frame(KDL::Rotation::RotX(next.alpha_rad),
                             KDL::Vector(next.a_m, 0.0, 0.0));
    }
    // KDL takes f_tip at joint angle 0 (it stores joint.pose(0)^-1 f_tip),
    // so the theta offset goes in front of it
    const KDL::Joint joint(KDL::Joint::RotZ, 1.0, row.theta_offset_rad);
    chain.addSegment(KDL::Segment(joint, joint.pose(0.0) * tip));
  }
  return chain;
}

struct KdlSolvers {
  KDL::Chain chain;
  KDL::ChainFkSolverPos_recursive fk;
  KDL::ChainJntToJacSolver jac;
  KDL::JntArray q;
  KDL::Frame frame;
  KDL::Jacobian J;
  explicit KdlSolvers(const OmniParams& p)
      : chain(omni_kdl_chain(p)), fk(chain), jac(chain), q(kOmniJoints),
        J(kOmniJoints) {}
  void run(const Joints& qv) {
    for (int i = 0; i < kOmniJoints; ++i) q(static_cast<unsigned>(i)) = qv[i];
    fk.JntToCart(q, frame);
    jac.JntToJac(q, J);
  }
  void result(Result* r) const {
    for (int i = 0; i < 3; ++i) {
      r->p[i] = frame.p(i);
      for (int j = 0; j < 3; ++j) r->R(i, j) = frame.M(i, j);
    }
    r->J = J.data;
  }
};

void BM_kdl_fk_jacobian(benchmark::State& state) {
  KdlSolvers kdl{OmniParams{}};
  over_samples(state, [&](const Joints& q) {
    kdl.run(q);
    benchmark::DoNotOptimize(kdl.frame);
    benchmark::DoNotOptimize(kdl.J.data);
  });
}
#endif

// ------------------------------------------------------------------ MuJoCo

#ifdef VMH_HAVE_MUJOCO
struct MujocoOmni {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  int site = -1;
  Eigen::Matrix<double, 3, kOmniJoints, Eigen::RowMajor> jacp, jacr;
  MujocoOmni() {
    char err[1000] = "";
    m = mj_loadXML(VMH_MODELS_DIR "/omni/omni.xml", nullptr, err, sizeof err);
    if (m == nullptr) {
      std::fprintf(stderr, "anchors_bench: %s/omni/omni.xml: %s\n",
                   VMH_MODELS_DIR, err);
      return;
    }
    d = mj_makeData(m);
    site = mj_name2id(m, mjOBJ_SITE, "wrist");
  }
  ~MujocoOmni() {
    if (d != nullptr) mj_deleteData(d);
    if (m != nullptr) mj_deleteModel(m);
  }
  MujocoOmni(const MujocoOmni&) = delete;
  MujocoOmni& operator=(const MujocoOmni&) = delete;
  bool ok() const { return d != nullptr && site >= 0 && m->nv == kOmniJoints; }
  void run(const Joints& q) {
    for (int i = 0; i < kOmniJoints; ++i) d->qpos[i] = q[i];
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_jacSite(m, d, jacp.data(), jacr.data(), site);
  }
  void result(Result* r) const {
    r->p = Eigen::Map<const Vec3>(d->site_xpos + 3 * site);
    r->R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
        d->site_xmat + 9 * site);
    r->J.topRows<3>() = jacp;
    r->J.bottomRows<3>() = jacr;
  }
};

void BM_mujoco_fk_jacobian(benchmark::State& state) {
  MujocoOmni mj;
  over_samples(state, [&](const Joints& q) {
    mj.run(q);
    benchmark::DoNotOptimize(mj.d->site_xpos[0]);
    benchmark::DoNotOptimize(mj.jacp);
    benchmark::DoNotOptimize(mj.jacr);
  });
}
#endif

// ------------------------------------------------------------- agreement

struct Diff {
  double p = 0, R = 0, J = 0;
  void add(const Result& a, const Result& b) {
    p = std::max(p, (a.p - b.p).cwiseAbs().maxCoeff());
    R = std::max(R, (a.R - b.R).cwiseAbs().maxCoeff());
    J = std::max(J, (a.J - b.J).cwiseAbs().maxCoeff());
  }
  bool report(const char* what) const {
    std::fprintf(stderr,
                 "anchors_bench: %s against omni_fk/omni_jacobian, %zu "
                 "samples: max |dp| = %.3g m, max |dR| = %.3g, max |dJ| = "
                 "%.3g\n",
                 what, kSamples, p, R, J);
    if (p <= kAgree && R <= kAgree && J <= kAgree) return true;
    std::fprintf(stderr, "anchors_bench: FAILED: %s disagrees (bound %.0e)\n",
                 what, kAgree);
    return false;
  }
};

bool check_all() {
  const OmniParams params;
  bool ok = true;
  Diff one_pass;
#ifdef VMH_HAVE_KDL
  Diff kdl_diff;
  KdlSolvers kdl{params};
#endif
#ifdef VMH_HAVE_MUJOCO
  Diff mj_diff;
  MujocoOmni mj;
  if (!mj.ok()) {
    std::fprintf(stderr, "anchors_bench: the MJCF Omni did not load\n");
    return false;
  }
#endif
  for (const Joints& q : samples()) {
    Result ref, r;
    omni_chain_twice(params, q, &ref);
    omni_one_pass(params, q, &r);
    one_pass.add(r, ref);
#ifdef VMH_HAVE_KDL
    kdl.run(q);
    kdl.result(&r);
    kdl_diff.add(r, ref);
#endif
#ifdef VMH_HAVE_MUJOCO
    mj.run(q);
    mj.result(&r);
    mj_diff.add(r, ref);
#endif
  }
  ok = one_pass.report("omni_fk_jacobian") && ok;
#ifdef VMH_HAVE_KDL
  ok = kdl_diff.report("KDL") && ok;
#else
  std::fprintf(stderr,
               "anchors_bench: KDL not found at configure time "
               "(liborocos-kdl-dev): kinematics/kdl_fk_jacobian skipped\n");
#endif
#ifdef VMH_HAVE_MUJOCO
  ok = mj_diff.report("MuJoCo") && ok;
#else
  std::fprintf(stderr,
               "anchors_bench: built without the testbed: "
               "kinematics/mujoco_fk_jacobian skipped\n");
#endif
  return ok;
}

void register_benchmarks() {
  benchmark::RegisterBenchmark("kinematics/omni_fk_jacobian",
                               BM_omni_fk_jacobian);
  benchmark::RegisterBenchmark("kinematics/omni_fk_then_jacobian",
                               BM_omni_fk_then_jacobian);
#ifdef VMH_HAVE_KDL
  benchmark::RegisterBenchmark("kinematics/kdl_fk_jacobian",
                               BM_kdl_fk_jacobian);
#endif
#ifdef VMH_HAVE_MUJOCO
  benchmark::RegisterBenchmark("kinematics/mujoco_fk_jacobian",
                               BM_mujoco_fk_jacobian);
#endif
}

}  // namespace
}  // namespace vmh

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!vmh::check_all()) {
    std::fprintf(stderr, "anchors_bench: aborting: an anchor disagrees\n");
    return 1;
  }
  vmh::register_benchmarks();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
