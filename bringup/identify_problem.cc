// The fit identify() solves (bringup/identify_problem.h): the pushed
// windows read from the recordings, the parameters as log-scales, and the
// weighted residuals of every window under an edit, simulated in parallel.
#include "bringup/identify_problem.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <exception>
#include <utility>

#include "controller/device_frame.h"
#include "device/stop_signal.h"
#include "output/parallel.h"
#include "runtime/stop.h"
#include "sim/sensor_model.h"

namespace vmh::bringup::detail {
namespace {

constexpr double kBadResidual = 1e6;   // a simulation that blew up
// half a quantization step in weighted units (a step is sqrt(12))
const double kHalfStep = std::sqrt(3.0);

// a SIGINT or SIGTERM during the fit (device/stop_signal.h): the
// simulations still queued are skipped and the fit ends here, before the
// verb writes anything
void identify_stop_if_asked() {
  runtime::throw_if_stopped("identify", "; nothing written");
}

}  // namespace

std::vector<Param> parse_fit(const std::vector<std::string>& fit) {
  std::vector<Param> out;
  for (const std::string& f : fit) {
    if (f == "mass") {
      out.push_back({"mass_scale"});
    } else if (f == "friction") {
      out.push_back({"friction_scale"});
    } else if (f == "damping") {
      out.push_back({"damping_scale"});
    } else if (f == "gains") {
      for (int i = 0; i < 3; ++i) {
        out.push_back({"motor_gain" + std::to_string(i + 1) + "_scale", i});
      }
    } else {
      throw IdentifyError("identify: unknown parameter '" + f +
                          "' to fit (expected mass, friction, damping, gains)");
    }
  }
  if (out.empty()) throw IdentifyError("identify: nothing to fit");
  return out;
}

sim::OmniModelEdit edit_at(const std::vector<Param>& params,
                           const Eigen::VectorXd& x,
                           const sim::OmniModelEdit& base) {
  sim::OmniModelEdit e = base;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const double s = std::exp(x[static_cast<Eigen::Index>(i)]);
    const Param& p = params[i];
    if (p.gain_motor >= 0) {
      e.motor_gain[p.gain_motor] *= s;
    } else if (p.name == "mass_scale") {
      e.mass_scale *= s;
    } else if (p.name == "friction_scale") {
      e.friction_scale *= s;
    } else {
      e.damping_scale *= s;
    }
  }
  return e;
}

double scale_of(const Param& p, const sim::OmniModelEdit& e) {
  if (p.gain_motor >= 0) return std::abs(e.motor_gain[p.gain_motor]);
  if (p.name == "mass_scale") return e.mass_scale;
  if (p.name == "friction_scale") return e.friction_scale;
  return e.damping_scale;
}

std::string scene_of(const Recording& r, const IdentifyOptions& o) {
  std::string scene = r.emulator_scene();
  if (!scene.empty()) return scene;
  if (o.default_scene.empty()) {
    throw IdentifyError("identify: recording " + r.dir +
                        " names no scene (meta.json emulator.scene) and no "
                        "default scene was given");
  }
  return o.default_scene;
}

void find_windows(const Recording& r, std::size_t index,
                  const IdentifyOptions& o, ResponseSimulator* sim,
                  std::vector<Window>* out) {
  const std::vector<std::size_t> good = r.good_rows();
  std::vector<Vec3> tau(r.rows);
  for (std::size_t k = 0; k < r.rows; ++k) {
    tau[k] = r.tau_sent_Nm(k);
    if (!tau[k].allFinite()) tau[k] = Vec3::Zero();
  }
  std::vector<std::pair<double, double>> pulses;  // [start, end] s
  for (std::size_t k = 0; k < r.rows; ++k) {
    if (tau[k].cwiseAbs().maxCoeff() <= 0.0) continue;
    const double t = r.t_s(k);
    if (!pulses.empty() && t - pulses.back().second <= o.before_s + o.after_s) {
      pulses.back().second = t;
    } else {
      pulses.emplace_back(t, t);
    }
  }
  for (const auto& [t_on, t_off] : pulses) {
    Window w;
    w.recording = index;
    w.sim = sim;
    Vec3 peak = Vec3::Zero();
    for (std::size_t k : good) {
      const double t = r.t_s(k);
      if (t < t_on - o.before_s || t > t_off + o.after_s) continue;
      w.input.t_s.push_back(t);
      w.input.tau_motor_Nm.push_back(tau[k]);
      w.measured.push_back(dh_to_device_joints(r.q_dh_rad(k)));
      peak = peak.cwiseMax(tau[k].cwiseAbs());
    }
    if (w.input.t_s.size() < 10) continue;  // too few readings to judge
    peak.maxCoeff(&w.motor);
    w.motor += 1;
    w.input.q0_device_rad = w.measured.front();
    // at rest before a pulse; a least-squares slope over 10 ms otherwise
    w.input.qdot0_device_rad_s =
        velocity_estimate(w.input.t_s, w.measured, 0, 0.01);
    out->push_back(std::move(w));
  }
}

Problem::Problem(std::vector<Window> windows, int threads)
    : windows_(std::move(windows)), threads_(threads) {
  const sim::SensorModel sensors(OmniParams(), true);
  for (int j = 0; j < 6; ++j) {
    weight_[j] = std::sqrt(12.0) / sensors.resolution_rad()[static_cast<std::size_t>(j)];
  }
  for (const Window& w : windows_) {
    offset_.push_back(size_);
    size_ += 6 * (w.measured.size() - 1);
  }
}

double Problem::lag1_correlation(const Eigen::VectorXd& r) const {
  double num = 0.0, den = 0.0;
  for (std::size_t w = 0; w < windows_.size(); ++w) {
    const std::size_t n = windows_[w].measured.size() - 1;
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t j = 0; j < 6; ++j) {
        const double a = r[static_cast<Eigen::Index>(offset_[w] + 6 * k + j)];
        den += a * a;
        if (k + 1 < n) num += a * r[static_cast<Eigen::Index>(offset_[w] + 6 * (k + 1) + j)];
      }
    }
  }
  return den > 0.0 ? num / den : 0.0;
}

std::vector<Eigen::VectorXd> Problem::residuals(
    const std::vector<sim::OmniModelEdit>& edits) const {
  std::vector<Eigen::VectorXd> out(edits.size(), Eigen::VectorXd::Zero(
                                                     static_cast<Eigen::Index>(size_)));
  const std::size_t nw = windows_.size();
  output::parallel_for(edits.size() * nw, threads_, [&](std::size_t task) {
    if (stop_requested()) return;  // thrown below, on this thread
    const std::size_t e = task / nw, w = task % nw;
    fill(windows_[w], edits[e], offset_[w], &out[e]);
  });
  identify_stop_if_asked();
  return out;
}

std::vector<Joints> Problem::simulate(std::size_t w,
                                      const sim::OmniModelEdit& edit) const {
  try {
    const SimulatedResponse r = windows_[w].sim->simulate(windows_[w].input, edit);
    if (r.finite) return r.q_device_rad;
  } catch (const std::exception&) {
  }
  return {};
}

void Problem::fill(const Window& w, const sim::OmniModelEdit& edit,
                   std::size_t at, Eigen::VectorXd* r) const {
  std::vector<Joints> q;
  try {
    const SimulatedResponse s = w.sim->simulate(w.input, edit);
    if (s.finite) q = s.q_device_rad;
  } catch (const std::exception&) {
    // an edit MuJoCo rejects counts as a very bad fit
  }
  const std::size_t n = w.measured.size() - 1;
  for (int j = 0; j < 6; ++j) {
    // the start is known only to within a sensor step, and the whole
    // simulated run carries that offset: take it out, as the constant
    // of at most half a step that fits best (else the fit bends the
    // physics to move the joints that barely move by that much)
    double mean = 0.0;
    for (std::size_t k = 1; k <= n && !q.empty(); ++k) {
      mean += weight_[j] * (q[k][j] - w.measured[k][j]) / static_cast<double>(n);
    }
    const double offset = std::clamp(mean, -kHalfStep, kHalfStep);
    for (std::size_t k = 1; k <= n; ++k) {
      const auto i = static_cast<Eigen::Index>(at + 6 * (k - 1) + static_cast<std::size_t>(j));
      (*r)[i] = q.empty() ? kBadResidual
                          : weight_[j] * (q[k][j] - w.measured[k][j]) - offset;
    }
  }
}

std::vector<std::vector<Joints>> simulate_all(const Problem& pb,
                                              const sim::OmniModelEdit& e,
                                              int threads) {
  std::vector<std::vector<Joints>> out(pb.windows().size());
  output::parallel_for(out.size(), threads, [&](std::size_t w) {
    if (!stop_requested()) out[w] = pb.simulate(w, e);
  });
  identify_stop_if_asked();
  return out;
}

}  // namespace vmh::bringup::detail
