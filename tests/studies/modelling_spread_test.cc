// The modelling spread read back from sensitivity.json and put beside the
// precision study's error (studies/modelling_spread.h).
#include "studies/modelling_spread.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sim/mujoco_util.h"

namespace vmh::studies {
namespace {

namespace fs = std::filesystem;

fs::path write_sensitivity(const std::string& text) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmh_modelling_spread";
  fs::create_directories(dir);
  std::ofstream(dir / "sensitivity.json") << text;
  return dir;
}

TEST(ModellingSpread, ReadsTheCaseAndSaysWhichDominates) {
  const fs::path dir = write_sensitivity(R"({"study": "sensitivity", "sweep_id": "ab",
    "modelling_spread": [
      {"case": "case1", "rms_path_error_mm": {"nominal": 4, "min": 3, "max": 5,
       "spread": 2, "over": "sample", "points": 16}},
      {"case": "case2", "rms_path_error_mm": {"nominal": 16, "min": 4, "max": 20,
       "spread": 16, "over": "one_at_a_time", "points": 19}}]})");
  const ModellingSpread s = read_modelling_spread(dir.string(), "case2");
  ASSERT_TRUE(s.present);
  EXPECT_EQ(s.spread_mm, 16.0);
  EXPECT_EQ(s.min_mm, 4.0);
  EXPECT_EQ(s.over, "one_at_a_time");
  EXPECT_EQ(s.points, 19);
  const auto j = modelling_spread_json(s, 1.6e-5);
  EXPECT_EQ(j.at("dominant"), "modelling");
  EXPECT_DOUBLE_EQ(j.at("spread_over_default_error").get<double>(), 16.0 / 1.6e-5);
  EXPECT_EQ(modelling_spread_json(s, 32.0).at("dominant"), "numerical");

  output::Chart chart;
  output::ChartSeries data;
  data.x = {0.01, 0.5, 4.0};
  data.y = {1e-2, 1e-4, 1e-9};
  chart.series.push_back(data);
  add_modelling_spread(&chart, s);
  ASSERT_EQ(chart.series.size(), 2u);
  EXPECT_EQ(chart.series[1].x, (std::vector<double>{0.01, 4.0}));
  EXPECT_EQ(chart.series[1].y, (std::vector<double>{16.0, 16.0}));
  EXPECT_TRUE(chart.series[1].dashed);

  EXPECT_THROW(read_modelling_spread(dir.string(), "case6"), sim::SimError);
  EXPECT_THROW(read_modelling_spread((dir / "none.json").string(), "case2"),
               sim::SimError);
  write_sensitivity(R"({"study": "precision"})");
  EXPECT_THROW(read_modelling_spread(dir.string(), "case2"), sim::SimError);
}

}  // namespace
}  // namespace vmh::studies
