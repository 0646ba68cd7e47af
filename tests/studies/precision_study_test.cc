// studies/precision_study.cc: the work-precision study of the closed loop.
//
// Independent truths:
// - the orders of the integrators: explicit/semi-implicit Euler and MuJoCo's
//   implicit-in-velocity Euler are first-order methods, classical RK4 is
//   fourth order (Hairer, Norsett & Wanner, Solving Ordinary Differential
//   Equations I, 2nd ed., sections II.1-II.3), when the right-hand side is
//   smooth. The smooth scene (tests/sim/scenes/case1_smooth.xml) is case 1
//   without the joints' dry friction, whose kink holds RK4 near order 2;
//   the closed-form placement takes the Gauss-Newton iteration count (a
//   discrete decision) out of the loop as well.
// - a least-squares slope of exact power-law data is the exponent;
// - a Pareto front drawn by hand.
// The runs are short (0.4 s of a script compressed into 4 s) and the
// ladders small, to keep the whole file near two seconds.
#include "studies/precision_study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>

#include "sim/mujoco_util.h"
#include "tests/support/mujoco_guard.h"

namespace {

using vmh::studies::fit_order;
using vmh::studies::Integrator;
using vmh::studies::OrderFit;
using vmh::studies::pareto_front;
using vmh::studies::PrecisionOptions;
using vmh::studies::PrecisionResult;
using vmh::studies::PrecisionRow;
using vmh::studies::run_precision_study;

const std::string kModels = VMH_MODELS_DIR;
const std::string kSmoothScene = VMH_TEST_SCENES_DIR "/case1_smooth.xml";

// a short run that moves: the thesis script compressed into 4 s puts the
// move off the path at 0.2 s, so 0.4 s covers the settle, the move and the
// start of the hold
PrecisionOptions short_study(const std::string& scene) {
  PrecisionOptions o;
  o.scene = scene;
  o.overrides = {"duration_s=4"};
  o.duration_s = 0.4;
  o.steps_s = {1e-3, 5e-4, 2.5e-4};
  o.min_timing_s = 0.0;  // one run per rung: timings are not tested
  o.max_repeats = 1;
  return o;
}

const OrderFit& fit_of(const PrecisionResult& r, Integrator i) {
  for (const OrderFit& f : r.fits) {
    if (f.integrator == i) return f;
  }
  ADD_FAILURE() << "no fit for " << vmh::studies::integrator_name(i);
  return r.fits.front();
}

// rms error per step for one integrator
std::map<double, double> errors_of(const PrecisionResult& r, Integrator i) {
  std::map<double, double> e;
  for (const PrecisionRow& row : r.rows) {
    if (row.integrator == i) e[row.step_s] = row.error.rms_mm;
  }
  return e;
}

TEST(FitOrder, RecoversTheExponentOfAPowerLaw) {
  const std::vector<double> h = {1e-3, 5e-4, 2e-4, 1e-4};
  std::vector<double> e;
  for (double x : h) e.push_back(3.0 * std::pow(x, 2.5));
  const OrderFit f = fit_order(h, e);
  EXPECT_EQ(f.points, 4);
  EXPECT_NEAR(f.order, 2.5, 1e-12);
  EXPECT_NEAR(f.log10_coefficient, std::log10(3.0), 1e-10);
}

TEST(FitOrder, SkipsZeroAndNonFiniteAndNeedsTwoPoints) {
  const OrderFit f = fit_order({1e-3, 5e-4, 2e-4}, {1e-2, 0.0, std::nan("")});
  EXPECT_EQ(f.points, 1);
  EXPECT_TRUE(std::isnan(f.order));
}

TEST(ParetoFront, MatchesAHandDrawnFront) {
  // (time, error): a and b trade off, c is beaten by b on both, d ties a's
  // time with a larger error, e is NaN
  const std::vector<double> t = {1.0, 2.0, 3.0, 1.0, std::nan("")};
  const std::vector<double> e = {5.0, 1.0, 2.0, 6.0, 0.1};
  const std::vector<bool> front = pareto_front(t, e);
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, false, false}));
}

TEST(PrecisionStudy, SmoothLoopShowsTheTextbookOrders) {
  vmh::testing::MujocoGuard guard;
  PrecisionOptions o = short_study(kSmoothScene);
  o.overrides.push_back("placement=closed");
  o.integrators = {Integrator::kEuler, Integrator::kRk4};
  o.reference_step_s = 5e-5;
  o.reference_check_step_s = 1e-4;
  const PrecisionResult r = run_precision_study(o);

  // Euler 1, RK4 4. Measured 1.003 and 4.01; the tolerances leave room for
  // the pre-asymptotic curvature of a four-rung ladder, and still tell the
  // methods apart by far
  const OrderFit& euler = fit_of(r, Integrator::kEuler);
  const OrderFit& rk4 = fit_of(r, Integrator::kRk4);
  EXPECT_GE(euler.points, 3);
  EXPECT_NEAR(euler.order, 1.0, 0.1);
  EXPECT_GE(rk4.points, 2);
  EXPECT_NEAR(rk4.order, 4.0, 0.4);

  for (const PrecisionRow& row : r.rows) {
    EXPECT_TRUE(row.error.finite) << row.step_s;
    EXPECT_EQ(row.mujoco_warnings, 0) << guard.warnings();
  }
  EXPECT_EQ(guard.warnings(), "");

  // the scene's own setting (Euler at 0.2 ms, tests/sim/scenes/) is not a
  // rung of the ladder, so the study adds it, marked as the default
  EXPECT_EQ(r.default_integrator, Integrator::kEuler);
  EXPECT_DOUBLE_EQ(r.default_step_s, 2e-4);
  int defaults = 0;
  for (const PrecisionRow& row : r.rows) {
    if (!row.is_default) continue;
    ++defaults;
    EXPECT_EQ(row.integrator, Integrator::kEuler);
    EXPECT_DOUBLE_EQ(row.step_s, 2e-4);
    EXPECT_EQ(row.substeps, 5);
  }
  EXPECT_EQ(defaults, 1);
  ASSERT_EQ(r.rows.size(), 4u + 3u);
}

TEST(PrecisionStudy, CaseOneAsComposed) {
  vmh::testing::MujocoGuard guard;
  PrecisionOptions o = short_study(kModels + "/cases/case1.xml");
  o.reference_step_s = 2.5e-5;
  o.reference_check_step_s = 5e-5;
  const PrecisionResult r = run_precision_study(o);

  // the scene's own setting is a row, and the study knows it: Euler at
  // 1 ms, one step per servo tick (models/cases/case1.xml), already a rung
  EXPECT_EQ(r.default_integrator, Integrator::kEuler);
  EXPECT_DOUBLE_EQ(r.default_step_s, 1e-3);
  int defaults = 0;
  for (const PrecisionRow& row : r.rows) {
    if (row.is_default) {
      ++defaults;
      EXPECT_EQ(row.integrator, Integrator::kEuler);
      EXPECT_DOUBLE_EQ(row.step_s, 1e-3);
      EXPECT_EQ(row.substeps, 1);
    }
  }
  EXPECT_EQ(defaults, 1);
  ASSERT_EQ(r.rows.size(), 3u + 3u + 3u);
  EXPECT_EQ(r.ticks, 400);

  // first-order methods stay first order with the dry friction on
  // (measured 1.0005 and 1.009)
  EXPECT_NEAR(fit_of(r, Integrator::kEuler).order, 1.0, 0.1);
  EXPECT_NEAR(fit_of(r, Integrator::kImplicit).order, 1.0, 0.1);
  // RK4's order drops (measured 2.3) but stays clearly above Euler's, and
  // at every step its error is far below Euler's (measured 5000x at 1 ms)
  EXPECT_GT(fit_of(r, Integrator::kRk4).order,
            fit_of(r, Integrator::kEuler).order + 0.5);
  const auto euler = errors_of(r, Integrator::kEuler);
  const auto rk4 = errors_of(r, Integrator::kRk4);
  for (const auto& [h, e_rk4] : rk4) {
    ASSERT_TRUE(euler.count(h)) << h;
    EXPECT_LT(e_rk4, euler.at(h) / 100.0) << "h = " << h;
  }

  // for each integrator the error falls with the step, rung by rung
  for (Integrator i :
       {Integrator::kEuler, Integrator::kImplicit, Integrator::kRk4}) {
    const auto e = errors_of(r, i);  // ascending h
    double previous = 0.0;
    for (const auto& [h, err] : e) {
      EXPECT_GT(err, previous) << vmh::studies::integrator_name(i) << " h " << h;
      previous = err;
    }
  }

  // the reference's own error is well below every error the study reports
  double smallest = 1e300;
  for (const PrecisionRow& row : r.rows) {
    smallest = std::min(smallest, row.error.rms_mm);
  }
  EXPECT_GT(r.reference.self_error.rms_mm, 0.0);
  EXPECT_LT(r.reference.self_error.rms_mm, smallest / 10.0);
  EXPECT_EQ(guard.warnings(), "");

  // the table: a header with units and one line per row
  const std::string csv = vmh::studies::precision_csv(r);
  std::istringstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("integrator,h_s,substeps_per_tick,rms_error_mm,"
                         "max_error_mm,",
                         0),
            0u);
  for (const char* col : {"wall_time_s", "cpu_time_s", "steps_per_s",
                          "on_front", "used_in_fit", "is_default"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  int lines = 0;
  std::string line;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, static_cast<int>(r.rows.size()));

  // the chart: one line per integrator, then the default's marker
  const vmh::output::Chart chart = vmh::studies::precision_chart(r);
  ASSERT_GE(chart.series.size(), 4u);
  EXPECT_TRUE(chart.x.log);
  EXPECT_TRUE(chart.y.log);
  EXPECT_EQ(chart.series[0].label, "euler");
  EXPECT_EQ(chart.series[0].x.size(), 3u);
  EXPECT_EQ(chart.series[3].x.size(), 1u);
}

TEST(PrecisionStudy, RefusesAStepThatDoesNotDivideTheServoPeriod) {
  vmh::testing::MujocoGuard guard;
  PrecisionOptions o = short_study(kModels + "/cases/case1.xml");
  o.steps_s = {3e-4};
  try {
    run_precision_study(o);
    FAIL() << "no error";
  } catch (const vmh::sim::SimError& e) {
    EXPECT_NE(std::string(e.what()).find("does not divide"), std::string::npos)
        << e.what();
  }
}

TEST(PrecisionStudy, RefusesADurationBeyondTheScript) {
  vmh::testing::MujocoGuard guard;
  PrecisionOptions o = short_study(kModels + "/cases/case1.xml");
  o.duration_s = 5.0;  // the script was set to 4 s
  EXPECT_THROW(run_precision_study(o), vmh::sim::SimError);
}

}  // namespace
