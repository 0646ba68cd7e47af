// The claims measured on a run's rows, one function per group (the
// thesis's cases 1-6, and case 7's), each with its prediction from the law
// at the rows' true poses (thesis/law_prediction.h). Internal to studies/:
// evaluate_claims() (claims.h) calls measure_claims() and adds what every
// claim carries (its window's distance from the path, regime and match).
#ifndef VMHAPTICS_THESIS_CLAIM_MEASURES_H_
#define VMHAPTICS_THESIS_CLAIM_MEASURES_H_

#include <deque>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "thesis/claims.h"
#include "thesis/law_prediction.h"

namespace vmh::thesis::detail {

// the law's prediction at a row's ground-truth pose, worked out when a
// claim first asks for it and kept (index as rows): the claims read the
// settled halves of a few segments, a small part of a run's rows
class Predictions {
 public:
  Predictions(const std::vector<TickRecord>& rows, const ControllerParams& p)
      : rows_(&rows), p_(p), slot_(rows.size(), -1) {}
  // (a deque: a reference returned stays valid as more are worked out)
  const LawPrediction& at(const TickRecord* r) const {
    int& slot = slot_[static_cast<std::size_t>(r - rows_->data())];
    if (slot < 0) {
      slot = static_cast<int>(at_.size());
      at_.push_back(predict(*r, p_));
    }
    return at_[static_cast<std::size_t>(slot)];
  }
  // at the ground-truth pose of a row, device frame: the row's true wrist
  // centre (omni_fk of q_true_dh) and the stylus axis of the same angles
  static LawPrediction predict(const TickRecord& r, const ControllerParams& p) {
    const OmniPose pose = omni_fk(p.omni, r.q_true_dh);
    return predict_static_law(p, r.p_true_mm,
                              base_to_device_vector(pose.R_base.col(2)),
                              r.q_true_dh);
  }
  const ControllerParams& params() const { return p_; }

 private:
  const std::vector<TickRecord>* rows_;
  ControllerParams p_;
  mutable std::vector<int> slot_;  // per row: its index in at_, or -1
  mutable std::deque<LawPrediction> at_;
};

// the claims of case `thesis_case` (1..7; none for another) on the rows
std::vector<Claim> measure_claims(int thesis_case,
                                  const std::vector<TickRecord>& rows,
                                  const sim::Case& the_case,
                                  const Predictions& pred);

}  // namespace vmh::thesis::detail

#endif  // VMHAPTICS_THESIS_CLAIM_MEASURES_H_
