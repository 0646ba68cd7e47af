// studies/thesis_svg: the thesis's theta and trajectory figures from a
// trace. A history denser than the plot is drawn as min/max bands whose
// extremes hold every row's value; a sparse one as every row's line; the
// columns are read by name and a missing one is named.
#include "thesis/thesis_svg.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "tests/support/svg_check.h"

namespace vmh::thesis {
namespace {

std::vector<ThesisSample> wave(int n) {
  std::vector<ThesisSample> s;
  for (int i = 0; i < n; ++i) {
    ThesisSample r;
    r.t_s = 0.001 * i;
    r.theta_v = {std::sin(0.01 * i)};
    r.theta_r = {std::sin(0.01 * i) + 0.1 * std::sin(0.7 * i)};
    r.p_mm = {50.0 * std::cos(0.001 * i), 50.0 * std::sin(0.001 * i), 0.0};
    s.push_back(r);
  }
  return s;
}

using vmh::testing::count;

TEST(ThesisSvgTest, DenseHistoriesAreBandsSparseOnesLines) {
  const ForceFieldPath path{"circle", {0, 0, 0}, 50.0};
  const std::string dense = thesis_svg(wave(5000), path, 300);
  EXPECT_EQ(testing::tag_problems(dense), "");
  EXPECT_EQ(count(dense, "class=\"band\""), 2u);  // theta_V and theta_R
  EXPECT_NE(dense.find("t (s)"), std::string::npos);
  EXPECT_EQ(count(dense, "class=\"trajectory\""), 200u);
  const std::string sparse = thesis_svg(wave(200), path, 300);
  EXPECT_EQ(testing::tag_problems(sparse), "");
  EXPECT_EQ(count(sparse, "class=\"band\""), 0u);
  // a sphere's three joints: three plots
  std::vector<ThesisSample> s3;
  for (int i = 0; i < 100; ++i) {
    ThesisSample r;
    r.t_s = 0.01 * i;
    for (double a : {0.1, 0.2, 0.3}) {
      r.theta_v.push_back(a * i);
      r.theta_r.push_back(a * i + 0.01);
    }
    s3.push_back(r);
  }
  EXPECT_EQ(count(thesis_svg(s3, {"sphere", {0, 0, 0}, 50.0}, 300), "class=\"theta\""), 3u);
}

TEST(ThesisSvgTest, ReadsTheColumnsByNameAndNamesAMissingOne) {
  const std::string csv =
      "t_s,p_x_mm,p_y_mm,p_z_mm,theta_v_1,theta_r_1,other\n"
      "0.001,1,2,3,0.5,0.25,x\n0.002,4,5,6,0.75,0.125,y\n";
  const std::vector<ThesisSample> s = thesis_samples_from_csv(csv);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[1].t_s, 0.002);
  EXPECT_EQ(s[1].p_mm[2], 6.0);
  EXPECT_EQ(s[1].theta_v, std::vector<double>{0.75});
  EXPECT_EQ(s[1].theta_r, std::vector<double>{0.125});
  try {
    thesis_samples_from_csv("t_s,p_x_mm,p_y_mm,p_z_mm,theta_v_1\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("theta_r_1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vmh::thesis
