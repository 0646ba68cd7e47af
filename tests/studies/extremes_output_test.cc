// The extreme-cases study's outputs (studies/extremes_output.cc): the
// observer's thinning keeps every bucket's lowest and highest point, and the
// figure draws one panel per scenario with its curve, the judged window and
// its outcome. No simulation: the rows and results are made up here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "output/svg_chart.h"
#include "studies/extremes_study.h"
#include "tests/support/svg_check.h"

namespace vmh::studies {
namespace {

// rows at 1 ms with a wavy observer and one sharp spike and dip
std::vector<TickRecord> wavy_rows(std::size_t n) {
  std::vector<TickRecord> rows(n);
  for (std::size_t k = 0; k < n; ++k) {
    rows[k].t_s = 1e-3 * static_cast<double>(k + 1);
    rows[k].energy_motor_J = 1e-3 * std::sin(0.05 * static_cast<double>(k));
  }
  rows[537].energy_motor_J = 5e-3;
  rows[538].energy_motor_J = -4e-3;
  return rows;
}

TEST(ThinEnergy, KeepsEveryBucketsLowestAndHighestInTimeOrder) {
  const std::vector<TickRecord> rows = wavy_rows(1000);
  const EnergyCurve e = thin_energy(rows, 100);  // buckets of 10 rows
  ASSERT_EQ(e.t_s.size(), e.energy_J.size());
  EXPECT_LE(e.t_s.size(), 200u);
  EXPECT_GE(e.t_s.size(), 100u);
  EXPECT_TRUE(std::is_sorted(e.t_s.begin(), e.t_s.end()));
  for (std::size_t b = 0; b < 100; ++b) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t k = 10 * b; k < 10 * b + 10; ++k) {
      lo = std::min(lo, rows[k].energy_motor_J);
      hi = std::max(hi, rows[k].energy_motor_J);
    }
    for (double want : {lo, hi}) {
      EXPECT_NE(std::find(e.energy_J.begin(), e.energy_J.end(), want),
                e.energy_J.end())
          << "bucket " << b;
    }
  }
  EXPECT_EQ(*std::max_element(e.energy_J.begin(), e.energy_J.end()), 5e-3);
  EXPECT_EQ(*std::min_element(e.energy_J.begin(), e.energy_J.end()), -4e-3);
  // fewer rows than buckets: every row
  const std::vector<TickRecord> few(rows.begin(), rows.begin() + 50);
  EXPECT_EQ(thin_energy(few, 400).t_s.size(), 50u);
}

TEST(ExtremesFigure, OnePanelPerScenarioWithItsWindowAndOutcome) {
  ExtremesResult r;
  for (const char* name : {"baseline", "gains_x10"}) {
    ExtremeResult s;
    s.scenario.name = name;
    s.simulated_s = kExtremeDurationS + kExtremeRestS;
    s.outcome = std::string(name) == "baseline" ? "ok" : "limit_cycle";
    r.scenarios.push_back(s);
    r.energy.push_back(thin_energy(wavy_rows(1000), 100));
  }
  const output::ChartGrid g = extremes_figure(r);
  ASSERT_EQ(g.panels.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const output::Chart& c = g.panels[i];
    EXPECT_EQ(c.title, r.scenarios[i].scenario.name);
    EXPECT_EQ(c.subtitle, r.scenarios[i].outcome);
    EXPECT_DOUBLE_EQ(c.x.min, 0.0);
    EXPECT_DOUBLE_EQ(c.x.max, kExtremeDurationS + kExtremeRestS);
    // the judged window: the rest's last kRestWindowS
    ASSERT_EQ(c.bands.size(), 1u);
    EXPECT_DOUBLE_EQ(std::min(c.bands[0].x0, c.bands[0].x1),
                     kExtremeDurationS + kExtremeRestS - kRestWindowS);
    // the observer in mJ, every thinned point
    const auto curve = std::find_if(c.series.begin(), c.series.end(),
                                    [](const output::ChartSeries& s) {
                                      return s.x.size() > 2;
                                    });
    ASSERT_NE(curve, c.series.end());
    ASSERT_EQ(curve->y.size(), r.energy[i].energy_J.size());
    EXPECT_DOUBLE_EQ(*std::max_element(curve->y.begin(), curve->y.end()), 5.0);
    // the end of the script, a vertical line
    EXPECT_TRUE(std::any_of(c.series.begin(), c.series.end(),
                            [](const output::ChartSeries& s) {
                              return s.x.size() == 2 && s.x[0] == kExtremeDurationS &&
                                     s.x[1] == kExtremeDurationS;
                            }));
  }
  EXPECT_NE(g.panels[0].subtitle_color, g.panels[1].subtitle_color);
  const std::string svg = output::chart_grid_svg(g);
  EXPECT_EQ(vmh::testing::tag_problems(svg), "");
  EXPECT_EQ(vmh::testing::count(svg, "<svg class=\"chart\""), 2u);
}

}  // namespace
}  // namespace vmh::studies
