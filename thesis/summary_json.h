// summary.json's pieces (docs/outputs.md), for every writer of that
// format: `run` (thesis/run_case.cc) and `hw run` (thesis/hw_run.cc).
#ifndef VMHAPTICS_THESIS_SUMMARY_JSON_H_
#define VMHAPTICS_THESIS_SUMMARY_JSON_H_

#include <array>
#include <cstdint>

#include <mujoco/mujoco.h>
#include <nlohmann/json.hpp>

#include "sim/mujoco_messages.h"
#include "thesis/claims.h"

namespace vmh::thesis {

// a claim with its sides, prediction and regime; the run's metrics
nlohmann::json claim_json(const Claim& c);
nlohmann::json metrics_json(const RunMetrics& m);
// summary.json's "mujoco_warnings": {count, kinds, messages}: the per-step
// warnings by kind (ClosedLoop::mujoco_warning_counts) plus what else
// MuJoCo said, and every text MuJoCo wrote, deduplicated
// (sim/mujoco_messages.h; docs/outputs.md)
nlohmann::json mujoco_warnings_json(
    const std::array<std::int64_t, mjNWARNING>& per_step,
    const sim::MujocoWarningTally& messages);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_SUMMARY_JSON_H_
