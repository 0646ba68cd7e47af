#include "thesis/hw_run.h"

#include <algorithm>
#include <optional>

#include "thesis/claims.h"
#include "thesis/run_case.h"

namespace vmh::thesis {

HwRunCase::HwRunCase(const std::string& scene,
                     const std::vector<std::string>& sets,
                     const std::string& model_file, double gain_scale)
    : loop_(std::make_unique<sim::ClosedLoop>(scene, sets,
                                              sim::omni_model_hook(model_file))),
      params_(loop_->controller_params()),
      thesis_case_(loop_->config().thesis_case),
      duration_s_(loop_->config().sim.duration_s),
      gain_scale_(gain_scale) {
  runtime::scale_gains(&params_, gain_scale);
}

void HwRunCase::configure(runtime::SessionOptions* so) const {
  runtime::configure_controller_session(params_, so);
  so->chain.reference = reference_params(thesis_case(), params_);
  so->duration_s = duration_s();
}

std::string realtime_disturbance(const runtime::SessionResult& r) {
  std::string why;
  const auto add = [&](const std::string& s) {
    why += (why.empty() ? "" : ", ") + s;
  };
  if (r.timing.overruns > 0) {
    add(std::to_string(r.timing.overruns) + " servo overruns");
  }
  for (const auto& [name, n] : r.read_errors) {
    add(std::to_string(n) + " reads " + name);
  }
  if (r.dropped > 0) add(std::to_string(r.dropped) + " records dropped");
  if (r.stop_reason.rfind("emulator_stalled", 0) == 0) add("an emulator stall");
  return why;
}

Json HwRunCase::run(runtime::OpenedDevice* dev, runtime::SessionOptions so,
                    runtime::SessionResult* result) const {
  configure(&so);
  // the metrics over every tick, the claims over a bounded sample: every
  // k-th tick, at most kMaxKeptTicks, as run keeps them
  const auto ticks = static_cast<std::int64_t>(
      std::llround(so.duration_s / params_.servo_period_s));
  const std::int64_t every =
      std::max<std::int64_t>(1, (ticks + kMaxKeptTicks - 1) / kMaxKeptTicks);
  const bool truth = dev->truth != nullptr;
  std::optional<MetricsAccumulator> metrics;
  if (truth) metrics.emplace(loop_->the_case());
  std::vector<TickRecord> rows;
  if (truth) {
    rows.reserve(static_cast<std::size_t>(std::min<std::int64_t>(
        kMaxKeptTicks + 1, ticks / every + 1)));
  }
  std::int64_t n = 0;
  so.on_record = [&](const TickRecord& r) {
    if (!truth) return;
    metrics->add(r);
    if (n++ % every == 0) rows.push_back(r);
  };
  *result = runtime::run_session(dev, so);

  Json summary{{"thesis_case", thesis_case()},
               {"gain_scale", gain_scale_},
               {"clock", result->clock},
               {"measured_every_ticks", every}};
  if (!truth || rows.empty()) {
    summary["claims"] = Json::array();
    summary["claims_measured_on"] =
        truth ? "nothing: the session recorded no tick"
              : "nothing: a real device has no ground truth for the thesis's "
                "claims";
    return summary;
  }
  const std::string disturbed =
      result->clock == "realtime" ? realtime_disturbance(*result) : "";
  summary["metrics"] = Json::parse(metrics_json(metrics->result()).dump());
  if (!disturbed.empty()) {
    summary["claims"] = Json::array();
    summary["claims_judged"] = false;
    summary["claims_not_judged_because"] =
        "the session did not keep real time (" + disturbed +
        "): its claims would measure the host, not the controller; run "
        "with --clock lockstep";
    summary["claims_measured_on"] = "nothing";
    return summary;
  }
  const std::vector<Claim> claims = evaluate_claims(thesis_case(), rows, loop_->the_case());
  bool pass = true;
  Json cj = Json::array();
  for (const Claim& c : claims) {
    cj.push_back(Json::parse(claim_json(c).dump()));
    pass &= c.pass;
  }
  summary["claims"] = cj;
  summary["claims_judged"] = true;
  summary["all_claims_pass"] = pass;
  summary["claims_measured_on"] = "the emulator's ground truth";
  return summary;
}

}  // namespace vmh::thesis
