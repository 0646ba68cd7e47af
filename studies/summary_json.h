// summary.json's pieces (docs/outputs.md), for every writer of that
// format: `run` (studies/run_case.cc) and `hw run` (studies/hw_run.cc).
#ifndef VMHAPTICS_STUDIES_SUMMARY_JSON_H_
#define VMHAPTICS_STUDIES_SUMMARY_JSON_H_

#include <array>
#include <cstdint>

#include <mujoco/mujoco.h>
#include <nlohmann/json.hpp>

#include "sim/mujoco_messages.h"
#include "studies/claims.h"

namespace vmh::studies {

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

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_SUMMARY_JSON_H_
