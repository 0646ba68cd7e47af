// The fit identify() solves (bringup/identify.h), not part of the public
// interface: the recordings' pushed windows (find_windows), the fitted
// parameters as log-scales of an OmniModelEdit (parse_fit, edit_at,
// scale_of), and the Problem, the weighted residuals of every window under
// an edit, simulated in parallel (identify_problem.cc).
#ifndef VMHAPTICS_BRINGUP_IDENTIFY_PROBLEM_H_
#define VMHAPTICS_BRINGUP_IDENTIFY_PROBLEM_H_

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "bringup/identify.h"
#include "bringup/recording.h"
#include "bringup/response_sim.h"
#include "controller/types.h"
#include "sim/omni_model_edit.h"

namespace vmh::bringup::detail {

// One pushed stretch of one recording, ready to simulate
struct Window {
  std::size_t recording = 0;
  int motor = 1;  // the motor that pushed hardest
  ResponseSimulator* sim = nullptr;
  ResponseInput input;
  std::vector<Joints> measured;  // device angles, rad
};

// Which scale a fitted parameter sets
struct Param {
  std::string name;
  int gain_motor = -1;  // 0..2 for a gain, else -1
};

// The fit's parameters, from IdentifyOptions::fit's names (throws
// IdentifyError naming an unknown one, or when there is none)
std::vector<Param> parse_fit(const std::vector<std::string>& fit);

// The edit at log-scales x over `base` (which holds the signs)
sim::OmniModelEdit edit_at(const std::vector<Param>& params,
                           const Eigen::VectorXd& x,
                           const sim::OmniModelEdit& base);

// a parameter's value in an edit (a gain's magnitude)
double scale_of(const Param& p, const sim::OmniModelEdit& e);

// the scene a recording is simulated in: its own, else the options'
// default (throws IdentifyError naming the recording when there is none)
std::string scene_of(const Recording& r, const IdentifyOptions& o);

// The recording's pushed windows: runs of rows with a nonzero torque sent,
// merged when closer than a window's margins, widened by them
void find_windows(const Recording& r, std::size_t index,
                  const IdentifyOptions& o, ResponseSimulator* sim,
                  std::vector<Window>* out);

// Everything the fit evaluates: weighted residuals of every window
class Problem {
 public:
  Problem(std::vector<Window> windows, int threads);

  std::size_t size() const { return size_; }
  Joints weighted(const Joints& dq) const {
    return dq.cwiseProduct(Eigen::Map<const Joints>(weight_));
  }

  // correlation of each residual with the next sample's of the same joint
  double lag1_correlation(const Eigen::VectorXd& r) const;
  const std::vector<Window>& windows() const { return windows_; }

  // residuals of each (edit, window) pair, in parallel; out[i] gets
  // edits[i]'s whole residual vector
  std::vector<Eigen::VectorXd> residuals(
      const std::vector<sim::OmniModelEdit>& edits) const;

  // one window simulated under `edit` (device angles), empty when it fails
  std::vector<Joints> simulate(std::size_t w,
                               const sim::OmniModelEdit& edit) const;

 private:
  // window w's weighted residuals under `edit` into (*r)[at...], less
  // each joint's best constant (the start's offset)
  void fill(const Window& w, const sim::OmniModelEdit& edit, std::size_t at,
            Eigen::VectorXd* r) const;

  std::vector<Window> windows_;
  int threads_;
  double weight_[6];
  std::vector<std::size_t> offset_;
  std::size_t size_ = 0;
};

// every window simulated under e (device angles; a window's series empty
// when its simulation failed), in parallel
std::vector<std::vector<Joints>> simulate_all(const Problem& pb,
                                              const sim::OmniModelEdit& e,
                                              int threads);

}  // namespace vmh::bringup::detail

#endif  // VMHAPTICS_BRINGUP_IDENTIFY_PROBLEM_H_
