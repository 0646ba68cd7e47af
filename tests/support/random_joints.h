// Reproducible random joint configurations for the tests.
#ifndef VMHAPTICS_TESTS_SUPPORT_RANDOM_JOINTS_H_
#define VMHAPTICS_TESTS_SUPPORT_RANDOM_JOINTS_H_

#include <random>

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh::testing {

// Draws joint angles uniformly in [lo, hi] (rad) from a fixed seed.
class JointSampler {
 public:
  explicit JointSampler(unsigned seed, double lo = -3.14159265358979,
                        double hi = 3.14159265358979)
      : rng_(seed), u_(lo, hi) {}

  Joints next() {
    Joints q;
    for (int i = 0; i < 6; ++i) q[i] = u_(rng_);
    return q;
  }

  // uniform inside the joint ranges of `p`
  Joints next_within(const OmniParams& p) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Joints q;
    for (int i = 0; i < 6; ++i) {
      q[i] = p.joint_lower_rad[i] +
             unit(rng_) * (p.joint_upper_rad[i] - p.joint_lower_rad[i]);
    }
    return q;
  }

 private:
  std::mt19937 rng_;
  std::uniform_real_distribution<double> u_;
};

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_RANDOM_JOINTS_H_
