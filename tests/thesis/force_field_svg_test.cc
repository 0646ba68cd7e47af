// The force-field figure: its arrows, read back from the SVG, point where
// the samples' forces point (projected on each panel's device axes), the
// trace's CSV is read by column name, and the document is well formed.
#include "thesis/force_field_svg.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "runtime/trace_writer.h"
#include "thesis/run_case.h"
#include "tests/support/svg_check.h"
#include "tests/support/constants.h"

namespace vmh::thesis {
namespace {

using vmh::testing::kPi;

// Samples on a circle of radius 55 mm about (0, 0, 5) in the device's x-y
// plane, each pulled back toward the 50 mm path with a tangential and a z
// part, so that no two directions repeat.
std::vector<ForceSample> ring(int n) {
  std::vector<ForceSample> s;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * kPi * i / n;
    ForceSample f;
    f.t_s = 0.01 * i;
    f.p_mm = {55.0 * std::cos(a), 55.0 * std::sin(a), 5.0 + std::sin(3 * a)};
    f.F_N = {-2.5 * std::cos(a) - 0.7 * std::sin(a),
             -2.5 * std::sin(a) + 0.7 * std::cos(a), -0.4 - 0.3 * std::cos(a)};
    s.push_back(f);
  }
  return s;
}

struct Arrow {
  double t_s, x1, y1, x2, y2;
};

// every panel's arrows, by panel tag, and the axes it says it draws
std::map<std::string, std::vector<Arrow>> arrows_of(
    const std::string& svg, std::map<std::string, std::string>* axes) {
  std::map<std::string, std::vector<Arrow>> out;
  const std::regex panel_re(
      R"re(<g class="panel" id="ff-(\w+)" data-axes="(\w,\w)">([\s\S]*?)</g>)re");
  const std::regex line_re(
      R"re(<line class="force" data-t-s="([^"]+)" x1="([^"]+)" y1="([^"]+)" x2="([^"]+)" y2="([^"]+)")re");
  for (auto p = std::sregex_iterator(svg.begin(), svg.end(), panel_re);
       p != std::sregex_iterator(); ++p) {
    (*axes)[(*p)[1]] = (*p)[2];
    const std::string body = (*p)[3];
    for (auto l = std::sregex_iterator(body.begin(), body.end(), line_re);
         l != std::sregex_iterator(); ++l) {
      out[(*p)[1]].push_back({std::stod((*l)[1]), std::stod((*l)[2]),
                              std::stod((*l)[3]), std::stod((*l)[4]),
                              std::stod((*l)[5])});
    }
  }
  return out;
}

int axis_index(char c) { return c - 'x'; }

// every arrow's direction against its sample's force, projected on the
// panel's axes (y up in the data, down in the pixels)
void expect_arrows_follow_forces(const std::vector<ForceSample>& samples,
                                 const std::string& svg,
                                 std::size_t panels) {
  std::map<double, const ForceSample*> by_t;
  for (const ForceSample& s : samples) by_t[s.t_s] = &s;
  std::map<std::string, std::string> axes;
  const auto arrows = arrows_of(svg, &axes);
  ASSERT_EQ(axes.size(), panels);
  for (const auto& [tag, list] : arrows) {
    const int a = axis_index(axes[tag][0]), b = axis_index(axes[tag][2]);
    EXPECT_GE(list.size(), 20u) << tag;
    for (const Arrow& w : list) {
      // t_s is written with 9 significant digits
      const auto it = by_t.lower_bound(w.t_s - 1e-7);
      ASSERT_TRUE(it != by_t.end() && std::abs(it->first - w.t_s) < 1e-7)
          << "arrow at t = " << w.t_s << " has no sample";
      const ForceSample& s = *it->second;
      const double drawn = std::atan2(-(w.y2 - w.y1), w.x2 - w.x1);
      const double force = std::atan2(s.F_N[b], s.F_N[a]);
      double diff = std::remainder(drawn - force, 2.0 * kPi);
      // px() keeps two decimals: a few hundredths of a pixel on arrows
      // tens of pixels long
      EXPECT_LT(std::abs(diff), 0.01) << tag << " t = " << w.t_s;
    }
  }
}

TEST(ForceFieldSvgTest, CircleArrowsPointAlongTheForcesInThePlane) {
  const std::vector<ForceSample> s = ring(400);
  const std::string svg = force_field_svg(s, {"circle", {0, 0, 5}, 50.0}, 40);
  EXPECT_EQ(testing::tag_problems(svg), "");
  EXPECT_NE(svg.find("id=\"ff-path-xy\""), std::string::npos);
  expect_arrows_follow_forces(s, svg, 1);
}

TEST(ForceFieldSvgTest, SphereHasThreeProjectionsWithTheirForces) {
  const std::vector<ForceSample> s = ring(300);
  const std::string svg = force_field_svg(s, {"sphere", {0, 0, 0}, 50.0}, 30);
  EXPECT_EQ(testing::tag_problems(svg), "");
  for (const char* tag : {"ff-xy", "ff-xz", "ff-zy"}) {
    EXPECT_NE(svg.find(std::string("id=\"") + tag + "\""), std::string::npos) << tag;
  }
  expect_arrows_follow_forces(s, svg, 3);
}

// The hand holds still for 900 of 1000 rows, then moves 90 mm along x: the
// arrows are spread along the path walked, 9 mm apart, so no more than one
// sits where the hand held still (evenly in time, nine of ten would).
TEST(ForceFieldSvgTest, ArrowsAreSpreadAlongThePathNotInTime) {
  std::vector<ForceSample> s;
  for (int i = 0; i < 1000; ++i) {
    ForceSample f;
    f.t_s = 0.01 * i;
    const double x = i < 900 ? 0.0 : 0.9 * (i - 900 + 1);
    f.p_mm = {x, 50.0, 0.0};
    f.F_N = {0.3, -1.0, 0.0};
    s.push_back(f);
  }
  const std::string svg = force_field_svg(s, {"circle", {0, 0, 0}, 50.0}, 10);
  std::map<std::string, std::string> axes;
  const auto arrows = arrows_of(svg, &axes);
  ASSERT_EQ(arrows.at("xy").size(), 10u);
  int at_rest = 0;
  for (const Arrow& w : arrows.at("xy")) at_rest += w.t_s < 9.0 ? 1 : 0;
  EXPECT_EQ(at_rest, 1);
  // the arrows' tails 9 mm apart along x: equally spaced in pixels
  std::vector<double> x;
  for (const Arrow& w : arrows.at("xy")) x.push_back(w.x1);
  std::sort(x.begin(), x.end());
  for (std::size_t i = 2; i < x.size(); ++i) {
    EXPECT_NEAR(x[i] - x[i - 1], x[1] - x[0], 0.05) << i;
  }
}

TEST(ForceFieldSvgTest, NoRowsGivesADocumentSayingSo) {
  const std::string svg = force_field_svg({}, {"circle", {0, 0, 0}, 50.0});
  EXPECT_EQ(testing::tag_problems(svg), "");
  EXPECT_NE(svg.find("no rows"), std::string::npos);
}

TEST(ForceFieldSvgTest, ReadsTheTraceColumnsByName) {
  // trace.csv's own header (one VM joint), two rows with marked values
  runtime::TraceLayout layout;
  layout.controller = true;
  layout.vm_dof = 1;
  layout.truth = true;
  layout.phases = {"settle"};
  const std::vector<std::string> cols = runtime::trace_columns(layout);
  std::string csv;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    csv += cols[i] + (i + 1 < cols.size() ? "," : "\n");
  }
  for (int row = 0; row < 2; ++row) {
    for (std::size_t i = 0; i < cols.size(); ++i) {
      std::string v = std::to_string(100 * row + static_cast<int>(i));
      if (cols[i] == "phase") v = "settle";
      csv += v + (i + 1 < cols.size() ? "," : "\n");
    }
  }
  const std::vector<ForceSample> s = force_samples_from_csv(csv);
  ASSERT_EQ(s.size(), 2u);
  auto column = [&](const char* name) {
    for (std::size_t i = 0; i < cols.size(); ++i) {
      if (cols[i] == name) return static_cast<double>(i);
    }
    return -1.0;
  };
  EXPECT_EQ(s[1].t_s, 100 + column("t_s"));
  EXPECT_EQ(s[1].p_mm[2], 100 + column("p_z_mm"));
  EXPECT_EQ(s[0].F_N[0], column("F_x_N"));
  EXPECT_EQ(s[1].F_N[2], 100 + column("F_z_N"));
}

TEST(ForceFieldSvgTest, AMissingColumnIsNamed) {
  try {
    force_samples_from_csv("t_s,p_x_mm,p_y_mm,p_z_mm,F_x_N,F_y_N\n0,1,2,3,4,5\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("F_z_N"), std::string::npos) << e.what();
  }
  try {
    force_samples_from_csv("t_s,p_x_mm,p_y_mm,p_z_mm,F_x_N,F_y_N,F_z_N\n0,1,x,3,4,5,6\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vmh::thesis
