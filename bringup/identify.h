// Identification: the MJCF Omni's uncertain parameters fitted to
// recordings of the device moving under known motor torques (issue 13),
// and the calibrated model written from the fit.
//
// Method. An output-error fit: each window of a recording where the
// motors pushed (a motor-test pulse, from 20 ms before it starts to
// 200 ms after it ends, so that friction's stopping shows) is simulated
// from its first measured state under the recorded torques
// (ResponseSimulator, nobody holding the stylus), and the residuals are
// simulated minus measured device joint angles t1..t6 (rad) at every
// sample after the first, each divided by its sensor's quantization noise
// (step / sqrt(12): 15000-count encoders on t1..t3, 11-bit potentiometers
// on t4..t6, sim::SensorModel). Levenberg-Marquardt minimises their sum
// of squares over the logarithms of the scales (so they stay positive),
// with a central finite-difference Jacobian (1 % steps) whose simulations
// run in parallel. sigma = s sqrt(diag((J^T J)^-1)) with s^2 the
// residual variance per degree of freedom, mapped from log to scale by
// the delta method (sigma_scale = fitted x sigma_log).
//
// Motor signs are a discrete choice made first, at the starting model:
// for each motor that pushed in some window, the sign that makes the
// simulated displacement point the way the measured one does (their
// cosine over the weighted joints and samples), "determined" when
// |cosine| >= 0.5. A cosine, not a cost: a model far off in mass or
// friction misses by about as much with either sign.
//
// The start is known only to within a sensor step and the whole simulated
// run carries that offset, so each window's residual series per joint
// loses the constant (at most half a step) that fits it best; without it
// the fit bent the physics to move barely-moving joints by that offset
// (mass off by 5 % on the test's pulses). Residuals of neighbouring
// samples repeat each other (staircases), so sigma is widened by the
// AR(1) factor sqrt((1 + rho) / (1 - rho)), rho their lag-one correlation.
//
// Identifiability (the physics). With gravity off (the thesis's scenes)
// and free motion only, M q'' + b q' + f sign(q') = K tau is unchanged
// when M, b, f and K are scaled together, so a global mass scale and the
// motor gains cannot both be found without an external reference
// (gravity, a known mass, a force sensor). By default the fit therefore
// holds the motor gains at their nominal values (the datasheet torque
// constants, an assumption) and fits mass, friction and damping scales;
// "gains" adds the three gain magnitudes, and when they are fitted with
// mass the result reports the near-degeneracy through the correlation
// matrix and its condition number (only the motor armature and the hand's
// mass on the grip, neither scaled, break the symmetry). Viscous damping
// is small in the model (0.5 mN m s/rad against 10 mN m of friction) and
// short pulses barely inform it: its sigma says so, and a scale whose
// relative sigma exceeds 25 % is reported as not identified.
//
// Measured (tests/bringup/identify_test.cc: pulses of 60, 80 and
// -60 mN m for 60 ms on motors 1, 2, 3 from rest, simulated on case1.xml
// under the true edit, quantized like the sensors): seeded mass x2 and
// friction x3 come back as 2.013 +- 0.016 and 3.006 +- 0.004 (sigma
// already widened x2.4), the residual RMS falls from 38 / 76 / 8 mrad
// (7.3 / 9.9 / 2.7 mm at the wrist) to 0.26 / 0.20 / 0.09 mrad (0.03 mm);
// damping comes out 0.05 +- 0.97, i.e. not identified. A clean set gives
// mass 1.002, friction 1.000; a flipped motor 2 is found (cosine -1).
// The tolerances the tests assert: mass 10 %, friction 20 %, and
// |fitted - true| < 4 sigma for both. On the emulator's own clean
// motor-test recordings (hw motor-test, same pulses) the fit gives mass
// 1.009 +- 0.001, friction 0.994 +- 0.0003 and damping 1.25 +- 0.02: the
// emulator is not exactly this simulation (its servo timing, its
// sensors), sigma covers the noise, not such model mismatch, and the
// damping it "finds" is that mismatch. Mass with the three gains:
// condition number about 50, flagged poorly conditioned (see above).
// A fit takes a few seconds (2 threads, ~30 iterations, 3 windows).
//
// The parameters are scales of the model's own values (OmniModelEdit):
// every Omni body's mass and inertia, every Omni joint's damping and
// friction (frictionloss), each motor's gear. Device convention for
// angles (t3 absolute); positions mm in the device frame.
#ifndef VMHAPTICS_BRINGUP_IDENTIFY_H_
#define VMHAPTICS_BRINGUP_IDENTIFY_H_

#include <Eigen/Core>

#include <stdexcept>
#include <string>
#include <vector>

#include "sim/omni_model_edit.h"
#include "bringup/recording.h"

namespace vmh::bringup {

// Recordings that cannot be fitted (no usable pulse, no scene to simulate
// with, an unknown parameter name): the message names them.
class IdentifyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct IdentifyOptions {
  // the scales to fit: any of "mass", "friction", "damping", "gains"
  std::vector<std::string> fit = {"mass", "friction", "damping"};
  bool find_signs = true;     // choose each pushed motor's sign first
  double before_s = 0.02;     // window start before a pulse starts
  double after_s = 0.2;       // window end after it ends
  // converged: every log-step within 0.1 sigma (widened as below)
  int max_iterations = 60;
  int threads = 2;            // simulations in parallel
  // the scene for recordings whose meta.json names none
  // (meta["emulator"]["scene"]); empty: such recordings are an error
  std::string default_scene;
  // a fit is poorly conditioned when two parameters' |correlation|
  // exceeds this
  double max_correlation = 0.99;
  double max_relative_sigma = 0.25;  // above it a scale is "not identified"
  // where the fit starts (the model as written by default); the scales
  // not fitted keep their values here, and signs are chosen relative to it
  sim::OmniModelEdit initial;
};

struct FittedParameter {
  std::string name;        // "mass_scale", "friction_scale", ...
  double nominal = 1.0;    // scale of the model as written
  double fitted = 1.0;
  double sigma = 0.0;      // one standard deviation, same unit
  std::string unit = "ratio";  // a dimensionless scale of the model's value
  bool identified = true;  // sigma / fitted <= max_relative_sigma
};

struct MotorSign {
  int motor = 1;             // 1..3
  int sign = 1;              // +1: as the model is written
  // cosine between simulated (sign as written) and measured displacement,
  // weighted joints over its windows: -1..1
  double agreement = 0.0;
  bool determined = false;   // |agreement| >= 0.5
};

// One window's pushed joint (device angle, rad) for the figure
struct WindowTrace {
  std::size_t recording = 0;
  int motor = 1;
  std::vector<double> t_s;
  std::vector<double> measured_rad, before_rad, after_rad;
};

struct RecordingFit {
  std::string dir;
  int windows = 0;
  std::size_t samples = 0;
  double rms_before_rad = 0.0;  // over t1..t6 and the samples
  double rms_after_rad = 0.0;
  double rms_before_mm = 0.0;   // wrist centre, device frame
  double rms_after_mm = 0.0;
};

struct IdentifyResult {
  std::vector<FittedParameter> parameters;
  Eigen::MatrixXd correlation;    // of the fitted parameters, in order
  double condition_number = 1.0;  // of the correlation matrix
  bool poorly_conditioned = false;
  std::string conditioning;       // one line: which pair, how correlated
  std::vector<MotorSign> signs;
  std::vector<RecordingFit> recordings;  // the recordings used, in order
  std::vector<WindowTrace> traces;
  std::vector<std::string> notes;  // recordings ignored, and why
  double cost_before = 0.0;        // weighted sum of squares / residuals
  double cost_after = 0.0;
  std::size_t residuals = 0;
  // the residuals' lag-one correlation and the factor it puts on sigma
  double residual_lag1_correlation = 0.0;
  double sigma_inflation = 1.0;
  int iterations = 0;
  bool converged = false;
  sim::OmniModelEdit edit;         // the fit, signs included
};

// Fits the model to the recordings' pushed windows. Recordings without
// tau_sent columns, or whose torques are all zero, are ignored with a
// note. Throws IdentifyError naming the recordings when none has a usable
// window, naming an unknown fit name, or naming a recording with no scene
// (and no default_scene); runtime::SignalStop (runtime/stop.h) when a
// SIGINT or SIGTERM came while a StopSignals lives (polled around each
// batch of simulations, the ones queued skipped).
IdentifyResult identify(const std::vector<Recording>& recordings,
                        const IdentifyOptions& options);

// Loads omni_xml_in (models/omni/omni.xml) standalone, applies `fitted`,
// and writes it as MJCF to path_out with an XML comment after the first
// line holding `provenance` (serial, date, recordings, fitted values).
// Throws sim::SimError naming the file that could not be read or written.
void write_calibrated_model(const sim::OmniModelEdit& fitted,
                            const std::string& omni_xml_in,
                            const std::string& path_out,
                            const std::string& provenance);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_IDENTIFY_H_
