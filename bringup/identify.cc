// Identification (bringup/identify.h): the recordings' pushed windows
// gathered, the motor signs chosen, Levenberg-Marquardt on the log-scales,
// the covariance, correlations and conditioning of the fit, and the
// residuals and traces before and after; the calibrated model written.
// The fit's problem itself (the windows, the residuals) is in
// identify_problem.cc.
#include "bringup/identify.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "bringup/identify_problem.h"
#include "bringup/response_sim.h"
#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "output/output_file.h"
#include "sim/mujoco_util.h"

namespace vmh::bringup {
namespace {

using detail::edit_at;
using detail::find_windows;
using detail::Param;
using detail::parse_fit;
using detail::Problem;
using detail::scale_of;
using detail::scene_of;
using detail::simulate_all;
using detail::Window;

constexpr double kLogStep = 0.01;      // finite-difference step, log scale
constexpr double kLogBound = 3.0;      // scales kept within e^+-3 (x0.05..x20)

// The pushed windows of every recording, simulated in one ResponseSimulator
// per scene (loading checks it once; the windows point into *sims). Each
// recording used gets its RecordingFit in res->recordings, each one ignored
// or not a motor test a note. Throws IdentifyError naming the recordings
// when none has a usable window.
std::vector<Window> collect_windows(
    const std::vector<Recording>& recordings, const IdentifyOptions& o,
    std::map<std::string, std::unique_ptr<ResponseSimulator>>* sims,
    IdentifyResult* res) {
  std::vector<Window> windows;
  for (std::size_t i = 0; i < recordings.size(); ++i) {
    const Recording& r = recordings[i];
    if (!r.has("tau_sent_1_Nm")) {
      res->notes.push_back(r.dir + ": ignored, no tau_sent columns");
      continue;
    }
    const std::size_t before = windows.size();
    const std::string scene = scene_of(r, o);
    auto& sim = (*sims)[scene];
    if (!sim) sim = std::make_unique<ResponseSimulator>(scene);
    find_windows(r, res->recordings.size(), o, sim.get(), &windows);
    if (windows.size() == before) {
      res->notes.push_back(
          r.dir + ": ignored, no torque sent (or too few readings around it)");
      continue;
    }
    if (r.verb != "hw motor-test") {
      res->notes.push_back(
          r.dir + ": a '" + r.verb +
          "' recording, simulated with nobody holding the stylus");
    }
    RecordingFit f;
    f.dir = r.dir;
    f.windows = static_cast<int>(windows.size() - before);
    for (std::size_t w = before; w < windows.size(); ++w) {
      f.samples += windows[w].measured.size();
    }
    res->recordings.push_back(f);
  }
  if (windows.empty()) {
    std::string names;
    for (const Recording& r : recordings) {
      names += (names.empty() ? "" : ", ") + r.dir;
    }
    throw IdentifyError(
        "identify: no usable motor pulse in " +
        (names.empty() ? std::string("(no recordings)") : names));
  }
  return windows;
}

// Each pushed motor's sign at the starting model: the one whose simulated
// displacement points the way the measured one does. The cosine between
// them (weighted joints, every sample) is scale-free, so a model far off
// in mass or friction still tells the direction where comparing the two
// signs' costs would not (both miss by about the same when the model
// moves much more than the arm did).
std::vector<MotorSign> choose_signs(const Problem& pb, int threads,
                                    sim::OmniModelEdit* base) {
  const std::vector<std::vector<Joints>> q = simulate_all(pb, *base, threads);
  std::vector<MotorSign> out;
  for (int m = 1; m <= 3; ++m) {
    double dot = 0.0, sim2 = 0.0, meas2 = 0.0;
    bool pushed = false;
    for (std::size_t w = 0; w < pb.windows().size(); ++w) {
      const Window& win = pb.windows()[w];
      if (win.motor != m || q[w].empty()) continue;
      pushed = true;
      for (std::size_t k = 1; k < win.measured.size(); ++k) {
        const Joints ds = pb.weighted(q[w][k] - q[w][0]);
        const Joints dm = pb.weighted(win.measured[k] - win.measured[0]);
        dot += ds.dot(dm);
        sim2 += ds.squaredNorm();
        meas2 += dm.squaredNorm();
      }
    }
    if (!pushed) continue;
    MotorSign ms;
    ms.motor = m;
    ms.agreement = sim2 > 0.0 && meas2 > 0.0 ? dot / std::sqrt(sim2 * meas2) : 0.0;
    ms.sign = ms.agreement < 0.0 ? -1 : 1;
    ms.determined = std::abs(ms.agreement) >= 0.5;
    if (ms.sign < 0) base->motor_gain[m - 1] = -base->motor_gain[m - 1];
    out.push_back(ms);
  }
  return out;
}

// Levenberg-Marquardt on the log-scales x of `params` over `base` (which
// holds the signs), with Marquardt's diagonal scaling and a central
// finite-difference Jacobian J = d r / d x (steps of kLogStep). Starts at
// x = 0 (the base), its residuals and its Jacobian.
class LogScaleFit {
 public:
  LogScaleFit(const Problem& pb, const std::vector<Param>& params,
              const sim::OmniModelEdit& base)
      : pb_(pb),
        params_(params),
        base_(base),
        num_params_(static_cast<Eigen::Index>(params.size())),
        num_residuals_(static_cast<Eigen::Index>(pb.size())),
        x_(Eigen::VectorXd::Zero(num_params_)) {
    r_ = pb_.residuals({edit_at(params_, x_, base_)})[0];
    cost_ = r_.squaredNorm();
    J_.resize(num_residuals_, num_params_);
    update_jacobian();
  }

  // the weighted sum of squares per residual at x
  double cost_per_residual() const {
    return cost_ / static_cast<double>(num_residuals_);
  }
  const Eigen::VectorXd& x() const { return x_; }
  const Eigen::VectorXd& residuals() const { return r_; }

  // Iterates until converged or max_iterations; counts the iterations
  void run(int max_iterations, int* iterations, bool* converged);

  // J at x, each column from the residuals at x +- kLogStep
  void update_jacobian();

  // the log-scales' covariance s^2 (J^T J)^-1, s^2 the residual variance
  // per degree of freedom widened by (1 + rho) / (1 - rho)
  Eigen::MatrixXd covariance(double rho) const {
    const double s2 = cost_ /
                      static_cast<double>(num_residuals_ - num_params_) *
                      (1.0 + rho) / (1.0 - rho);
    return s2 * (J_.transpose() * J_)
                    .completeOrthogonalDecomposition()
                    .pseudoInverse();
  }

 private:
  bool step(const Eigen::MatrixXd& A, const Eigen::VectorXd& g,
            bool* converged);
  bool within_uncertainty(const Eigen::MatrixXd& A,
                          const Eigen::VectorXd& dx) const;

  const Problem& pb_;
  const std::vector<Param>& params_;
  const sim::OmniModelEdit& base_;
  Eigen::Index num_params_;
  Eigen::Index num_residuals_;
  Eigen::VectorXd x_;  // log-scales
  Eigen::VectorXd r_;  // weighted residuals at x_
  double cost_ = 0.0;  // r_'s squared norm
  Eigen::MatrixXd J_;
  double lambda_ = 1e-3;
};

void LogScaleFit::update_jacobian() {
  std::vector<sim::OmniModelEdit> edits;
  for (Eigen::Index p = 0; p < num_params_; ++p) {
    for (double s : {+1.0, -1.0}) {
      Eigen::VectorXd xp = x_;
      xp[p] += s * kLogStep;
      edits.push_back(edit_at(params_, xp, base_));
    }
  }
  const std::vector<Eigen::VectorXd> rs = pb_.residuals(edits);
  for (Eigen::Index p = 0; p < num_params_; ++p) {
    J_.col(p) = (rs[static_cast<std::size_t>(2 * p)] -
                 rs[static_cast<std::size_t>(2 * p + 1)]) /
                (2.0 * kLogStep);
  }
}

void LogScaleFit::run(int max_iterations, int* iterations, bool* converged) {
  for (*iterations = 0; *iterations < max_iterations;) {
    ++*iterations;
    const Eigen::MatrixXd A = J_.transpose() * J_;
    const Eigen::VectorXd g = J_.transpose() * r_;
    if (!step(A, g, converged)) {
      // no direction lowers the cost: a minimum within the step's reach
      *converged = true;
    }
    if (*converged) break;
    update_jacobian();
  }
}

// One iteration's step: up to 8 tries, lambda raised 4x after each that
// does not lower the cost, lowered 3x on the one that does, which is
// taken; false when none did. Sets *converged when the step taken was
// small against the parameters' uncertainty or barely lowered the cost.
bool LogScaleFit::step(const Eigen::MatrixXd& A, const Eigen::VectorXd& g,
                       bool* converged) {
  bool stepped = false;
  for (int tries = 0; tries < 8 && !stepped; ++tries) {
    Eigen::MatrixXd Ad = A;
    Ad.diagonal() += lambda_ * A.diagonal().cwiseMax(1e-12);
    Eigen::VectorXd dx = Ad.ldlt().solve(-g);
    const Eigen::VectorXd xn =
        (x_ + dx).cwiseMax(-kLogBound).cwiseMin(kLogBound);
    dx = xn - x_;
    const Eigen::VectorXd rn = pb_.residuals({edit_at(params_, xn, base_)})[0];
    const double cn = rn.squaredNorm();
    if (cn < cost_) {
      const double gain = (cost_ - cn) / cost_;
      x_ = xn;
      r_ = rn;
      cost_ = cn;
      lambda_ = std::max(lambda_ / 3.0, 1e-7);
      stepped = true;
      if (within_uncertainty(A, dx) || gain < 1e-9) *converged = true;
    } else {
      lambda_ *= 4.0;
    }
  }
  return stepped;
}

// done when the step is small against the parameters' own uncertainty
// (or the cost no longer moves): further digits mean nothing
bool LogScaleFit::within_uncertainty(const Eigen::MatrixXd& A,
                                     const Eigen::VectorXd& dx) const {
  const double rho = std::clamp(pb_.lag1_correlation(r_), 0.0, 0.99);
  const Eigen::VectorXd sd_log =
      (cost_ / static_cast<double>(num_residuals_ - num_params_) * (1.0 + rho) /
       (1.0 - rho) *
       A.completeOrthogonalDecomposition().pseudoInverse().diagonal())
          .cwiseMax(0.0)
          .cwiseSqrt();
  return (dx.cwiseAbs().array() <= 0.1 * sd_log.array() + 1e-6).all();
}

// the correlation matrix of covariance cov, whose standard deviations are sd
Eigen::MatrixXd correlation_of(const Eigen::MatrixXd& cov,
                               const Eigen::VectorXd& sd) {
  const Eigen::Index P = cov.rows();
  Eigen::MatrixXd correlation = Eigen::MatrixXd::Identity(P, P);
  for (Eigen::Index i = 0; i < P; ++i) {
    for (Eigen::Index j = 0; j < P; ++j) {
      if (i != j && sd[i] > 0.0 && sd[j] > 0.0) {
        correlation(i, j) = cov(i, j) / (sd[i] * sd[j]);
      }
    }
  }
  return correlation;
}

// The most correlated pair of parameters: their correlation, and their
// names into res->conditioning (left empty with one parameter)
double most_correlated_pair(const std::vector<Param>& params,
                            IdentifyResult* res) {
  const auto P = static_cast<Eigen::Index>(params.size());
  double worst = 0.0;
  for (Eigen::Index i = 0; i < P; ++i) {
    for (Eigen::Index j = i + 1; j < P; ++j) {
      if (std::abs(res->correlation(i, j)) > std::abs(worst)) {
        worst = res->correlation(i, j);
        res->conditioning = params[static_cast<std::size_t>(i)].name + " and " +
                            params[static_cast<std::size_t>(j)].name;
      }
    }
  }
  return worst;
}

// free motion without gravity: scaling masses, damping, friction and
// gains together changes nothing but the parts mass_scale leaves alone
// (the motors' armature, the hand's mass on the grip), so the fit
// separates mass from gain only by trusting those assumed values
bool fits_mass_and_gains(const std::vector<Param>& params) {
  bool mass = false, gains = false;
  for (const Param& p : params) {
    mass = mass || p.name == "mass_scale";
    gains = gains || p.gain_motor >= 0;
  }
  return mass && gains;
}

// The fit's conditioning from res->correlation: the condition number, the
// most correlated pair, whether it is poorly conditioned (a pair beyond
// max_correlation, or mass with the gains), and the line that says so
void judge_conditioning(const std::vector<Param>& params,
                        double max_correlation, IdentifyResult* res) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(res->correlation);
  const double lo = eig.eigenvalues().minCoeff(),
               hi = eig.eigenvalues().maxCoeff();
  res->condition_number =
      lo > 0.0 ? hi / lo : std::numeric_limits<double>::infinity();
  const double worst = most_correlated_pair(params, res);
  res->poorly_conditioned = std::abs(worst) > max_correlation;
  const bool degenerate = fits_mass_and_gains(params);
  res->poorly_conditioned = res->poorly_conditioned || degenerate;
  std::ostringstream s;
  s << (res->conditioning.empty()
            ? "one parameter"
            : res->conditioning + " correlated " + std::to_string(worst))
    << "; condition number " << res->condition_number
    << (degenerate
            ? ": poorly conditioned by the physics: mass and motor gains are "
              "separated only through the assumed motor armature and hand mass "
              "(free motion, no gravity, no force reference)"
        : res->poorly_conditioned
            ? ": poorly conditioned (not separable from these recordings)"
            : ": well conditioned");
  res->conditioning = s.str();
}

// each parameter's fitted scale in `edit` and its sigma, sd_log[i] being
// its log's standard deviation
std::vector<FittedParameter> fitted_parameters(const std::vector<Param>& params,
                                               const sim::OmniModelEdit& edit,
                                               const Eigen::VectorXd& sd_log,
                                               double max_relative_sigma) {
  std::vector<FittedParameter> out;
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(params.size()); ++i) {
    FittedParameter fp;
    fp.name = params[static_cast<std::size_t>(i)].name;
    fp.fitted = scale_of(params[static_cast<std::size_t>(i)], edit);
    fp.sigma = fp.fitted * sd_log[i];  // delta method from the log
    fp.identified = fp.sigma <= max_relative_sigma * fp.fitted;
    out.push_back(fp);
  }
  return out;
}

// the wrist centre of device angles q, device frame, mm
Vec3 wrist_mm(const Joints& q_device) {
  const OmniParams omni;
  return base_to_device_mm(omni, omni_fk(omni, device_to_dh_joints(q_device)).p_base_m);
}

// RMS over the windows of one recording (rad over t1..t6, mm at the wrist)
void recording_rms(const Problem& pb, std::size_t rec,
                   const std::vector<std::vector<Joints>>& sim, double* rad,
                   double* mm) {
  double s_rad = 0.0, s_mm = 0.0;
  std::size_t n = 0;
  for (std::size_t w = 0; w < pb.windows().size(); ++w) {
    const Window& win = pb.windows()[w];
    if (win.recording != rec) continue;
    for (std::size_t k = 1; k < win.measured.size(); ++k) {
      if (sim[w].empty()) return void(*rad = *mm = std::nan(""));
      s_rad += (sim[w][k] - win.measured[k]).squaredNorm() / 6.0;
      s_mm += (wrist_mm(sim[w][k]) - wrist_mm(win.measured[k])).squaredNorm();
      ++n;
    }
  }
  *rad = n ? std::sqrt(s_rad / static_cast<double>(n)) : 0.0;
  *mm = n ? std::sqrt(s_mm / static_cast<double>(n)) : 0.0;
}

// Each recording's RMS residuals and each window's pushed joint before
// (the model as written, signs as written) and after the fit (res->edit)
void before_and_after(const Problem& pb, int threads, IdentifyResult* res) {
  const std::vector<std::vector<Joints>> q0 = simulate_all(pb, {}, threads);
  const std::vector<std::vector<Joints>> q1 =
      simulate_all(pb, res->edit, threads);
  for (std::size_t i = 0; i < res->recordings.size(); ++i) {
    RecordingFit& f = res->recordings[i];
    recording_rms(pb, i, q0, &f.rms_before_rad, &f.rms_before_mm);
    recording_rms(pb, i, q1, &f.rms_after_rad, &f.rms_after_mm);
  }
  for (std::size_t w = 0; w < pb.windows().size(); ++w) {
    const Window& win = pb.windows()[w];
    WindowTrace t;
    t.recording = win.recording;
    t.motor = win.motor;
    t.t_s = win.input.t_s;
    const int j = win.motor - 1;
    for (std::size_t k = 0; k < win.measured.size(); ++k) {
      t.measured_rad.push_back(win.measured[k][j]);
      t.before_rad.push_back(q0[w].empty() ? std::nan("") : q0[w][k][j]);
      t.after_rad.push_back(q1[w].empty() ? std::nan("") : q1[w][k][j]);
    }
    res->traces.push_back(std::move(t));
  }
}

}  // namespace

IdentifyResult identify(const std::vector<Recording>& recordings,
                        const IdentifyOptions& o) {
  const std::vector<Param> params = parse_fit(o.fit);
  IdentifyResult res;
  // one simulator per scene: loading checks it once
  std::map<std::string, std::unique_ptr<ResponseSimulator>> sims;
  std::vector<Window> windows = collect_windows(recordings, o, &sims, &res);
  const int threads = std::max(1, o.threads);
  const Problem pb(std::move(windows), threads);
  const auto P = static_cast<Eigen::Index>(params.size());
  const auto N = static_cast<Eigen::Index>(pb.size());
  if (N <= P) throw IdentifyError("identify: fewer readings than parameters");

  sim::OmniModelEdit base = o.initial;
  if (o.find_signs) res.signs = choose_signs(pb, threads, &base);

  LogScaleFit fit(pb, params, base);
  res.cost_before = fit.cost_per_residual();
  fit.run(o.max_iterations, &res.iterations, &res.converged);
  res.cost_after = fit.cost_per_residual();
  res.residuals = pb.size();
  res.edit = edit_at(params, fit.x(), base);
  fit.update_jacobian();  // at the solution, for the covariance

  // covariance of the log-scales, s^2 (J^T J)^-1, widened for residuals
  // that are not independent: quantization error and model error run in
  // staircases, so neighbouring samples repeat each other. An AR(1)
  // reading of the residuals' lag-one correlation rho gives the factor
  // (1 + rho) / (1 - rho) on the variance.
  res.residual_lag1_correlation = pb.lag1_correlation(fit.residuals());
  const double rho = std::clamp(res.residual_lag1_correlation, 0.0, 0.99);
  res.sigma_inflation = std::sqrt((1.0 + rho) / (1.0 - rho));
  const Eigen::MatrixXd cov = fit.covariance(rho);
  const Eigen::VectorXd sd = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  res.correlation = correlation_of(cov, sd);
  judge_conditioning(params, o.max_correlation, &res);
  res.parameters =
      fitted_parameters(params, res.edit, sd, o.max_relative_sigma);

  before_and_after(pb, threads, &res);
  return res;
}

void write_calibrated_model(const sim::OmniModelEdit& fitted,
                            const std::string& omni_xml_in,
                            const std::string& path_out,
                            const std::string& provenance) {
  // MuJoCo writes the file itself; the comment goes in after, and the
  // whole replaces path_out at once
  const std::string tmp = path_out + ".mujoco.xml";
  sim::save_edited_model_xml(
      omni_xml_in, [&](mjModel* m) { sim::apply_omni_edit(m, fitted); }, tmp);
  std::ifstream in(tmp);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  std::remove(tmp.c_str());
  std::string xml = text.str();
  // "--" may not appear inside an XML comment
  std::string note = provenance;
  for (std::size_t p = note.find("--"); p != std::string::npos; p = note.find("--", p)) {
    note.replace(p, 2, "- -");
  }
  const std::size_t eol = xml.find('\n');
  const std::string comment = "<!-- " + note + " -->\n";
  xml.insert(eol == std::string::npos ? xml.size() : eol + 1, comment);
  output::write_file_atomically(path_out, xml);
}

}  // namespace vmh::bringup
