// thesis/plot_svg.cc on real closed-loop runs (case 2: circle, case 5: sphere,
// 20 s each): the documents are well-formed SVG, the views show the two
// snapshots the thesis shows (their times in the titles, three projections
// for the sphere), the force arrow is the commanded force times the stated
// scale, drawn from p, and the histories are decimated.
//
// With VMH_PLOT_SVG_DIR set, the documents are also written there
// (caseN_views.svg, caseN_history.svg) for a look.
#include "thesis/plot_svg.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "sim/closed_loop.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/svg_check.h"

namespace vmh::thesis {
using namespace vmh::sim;  // NOLINT(build/namespaces): the testbed's types
namespace {

using vmh::testing::count;
using vmh::testing::tag_problems;

std::string scene(int n) {
  return std::string(VMH_MODELS_DIR) + "/cases/case" + std::to_string(n) +
         ".xml";
}

struct CaseRun {
  std::unique_ptr<ClosedLoop> loop;
  std::vector<TickRecord> rows;
  std::string views, history;
};

// one whole run per case, shared by the tests (about half a second each)
const CaseRun& run(int n) {
  static std::map<int, std::unique_ptr<CaseRun>> runs;
  std::unique_ptr<CaseRun>& slot = runs[n];
  if (!slot) {
    testing::MujocoGuard guard;
    auto r = std::make_unique<CaseRun>();
    r->loop = std::make_unique<ClosedLoop>(
        scene(n), std::vector<std::string>{"duration_s=20"});
    r->rows.resize(static_cast<std::size_t>(r->loop->ticks_per_run()));
    for (TickRecord& row : r->rows) r->loop->tick(&row);
    r->views = views_svg(r->rows, r->loop->the_case());
    r->history = history_svg(r->rows, r->loop->the_case());
    if (const char* dir = std::getenv("VMH_PLOT_SVG_DIR")) {
      const std::string base = std::string(dir) + "/case" + std::to_string(n);
      std::ofstream(base + "_views.svg") << r->views;
      std::ofstream(base + "_history.svg") << r->history;
    }
    slot = std::move(r);
  }
  return *slot;
}

// The row the views should show for `segment`: nearest the middle of its
// settled half (first of equals).
const TickRecord& snapshot_row(const CaseRun& r, const std::string& segment) {
  const ScriptSegment* seg = nullptr;
  for (const ScriptSegment& s : r.loop->script().segments()) {
    if (s.name == segment) seg = &s;
  }
  EXPECT_NE(seg, nullptr) << segment;
  const double mid = 0.5 * (seg->settled_from_s() + seg->t1_s);
  std::size_t best = 0;
  for (std::size_t i = 1; i < r.rows.size(); ++i) {
    if (std::abs(r.rows[i].t_s - mid) < std::abs(r.rows[best].t_s - mid)) {
      best = i;
    }
  }
  return r.rows[best];
}

// the attributes of the element with id="id" (empty if none)
std::map<std::string, std::string> element(const std::string& doc, const std::string& id) {
  std::map<std::string, std::string> a;
  const std::size_t at = doc.find("id=\"" + id + "\"");
  if (at == std::string::npos) return a;
  const std::size_t lt = doc.rfind('<', at), gt = doc.find('>', at);
  const std::string el = doc.substr(lt + 1, gt - lt - 1);
  a["<name>"] = el.substr(0, el.find(' '));
  static const std::regex kAttr(R"re(([A-Za-z0-9:-]+)="([^"]*)")re");
  for (std::sregex_iterator m(el.begin(), el.end(), kAttr), end; m != end; ++m) {
    a[(*m)[1].str()] = (*m)[2].str();
  }
  return a;
}

double number(const std::map<std::string, std::string>& a, const std::string& key) {
  const auto it = a.find(key);
  if (it == a.end()) {
    ADD_FAILURE() << "no attribute " << key;
    return std::nan("");
  }
  return std::stod(it->second);
}

TEST(PlotSvgTest, DocumentsAreWellFormedSvg) {
  for (int n : {2, 5}) {
    const CaseRun& r = run(n);
    for (const std::string* doc : {&r.views, &r.history}) {
      SCOPED_TRACE("case" + std::to_string(n) + (doc == &r.views ? " views" : " history"));
      EXPECT_EQ(doc->rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
      EXPECT_NE(doc->find("version=\"1.1\""), std::string::npos);
      EXPECT_NE(doc->find("viewBox=\"0 0 "), std::string::npos);
      EXPECT_EQ(tag_problems(*doc), "");
      EXPECT_EQ(count(*doc, "<svg"), 1u);
      EXPECT_EQ(count(*doc, "</svg>"), 1u);
      EXPECT_GT(count(*doc, "<polyline"), 0u);
      EXPECT_GT(count(*doc, "<line"), 0u);
      EXPECT_EQ(doc->find("nan"), std::string::npos);
      EXPECT_EQ(doc->find("inf"), std::string::npos);
    }
  }
  // no rows: still a document
  const CaseRun& r = run(2);
  for (const std::string& doc : {views_svg({}, r.loop->the_case()), history_svg({}, r.loop->the_case())}) {
    EXPECT_EQ(tag_problems(doc), "");
    EXPECT_NE(doc.find("no rows"), std::string::npos);
  }
}

// The titles carry the snapshot's time (the row nearest the middle of the
// settled half of each segment) and the case's name.
TEST(PlotSvgTest, ViewTitlesNameTheSnapshotTimes) {
  for (int n : {2, 5}) {
    const CaseRun& r = run(n);
    const int panels_per_snapshot = n == 5 ? 3 : 1;
    for (const auto& [segment, what] :
         std::vector<std::pair<std::string, std::string>>{
             {"off_out_misaligned", "RM off the path"},
             {"on_misaligned_a", "RM on the path"}}) {
      const TickRecord& row = snapshot_row(r, segment);
      EXPECT_EQ(r.loop->script().segments()[static_cast<std::size_t>(row.segment)].name,
                segment);
      char t[64];
      std::snprintf(t, sizeof t, " (t = %.3f s, d = ", row.t_s);
      const std::string title = "case" + std::to_string(n) + ": " + what + t;
      EXPECT_EQ(count(r.views, title), static_cast<std::size_t>(panels_per_snapshot))
          << title;
    }
  }
}

TEST(PlotSvgTest, CircleHasTwoPanelsSphereThreeProjectionsEach) {
  EXPECT_EQ(count(run(2).views, "class=\"panel\""), 2u);
  EXPECT_FALSE(element(run(2).views, "panel-off").empty());
  EXPECT_FALSE(element(run(2).views, "panel-on").empty());
  const std::string& v = run(5).views;
  EXPECT_EQ(count(v, "class=\"panel\""), 6u);
  for (const char* snap : {"off", "on"}) {
    for (const char* view : {"xy", "xz", "zy"}) {
      const std::string tag = std::string(snap) + "-" + view;
      EXPECT_EQ(element(v, "panel-" + tag)["<name>"], "g") << tag;
      EXPECT_EQ(element(v, "path-" + tag)["<name>"], "circle") << tag;
      EXPECT_EQ(element(v, "force-" + tag)["<name>"], "line") << tag;
    }
  }
  for (const char* view : {"x-y view", "x-z view", "z-y view"}) {
    EXPECT_EQ(count(v, view), 2u) << view;
  }
  for (const char* label : {">x_mm<", ">y_mm<", ">z_mm<"}) {
    EXPECT_EQ(count(v, label), 4u) << label;
  }
}

// The line slider (case 7): one view in its plane, like the circle, its
// path a line through the pivot along the device y axis (x1 = x2 at the
// pivot's x, spanning the frame), no thesis figures to cite
TEST(PlotSvgTest, LineIsDrawnAsALineInItsPlane) {
  const CaseRun& r = run(7);
  const std::string& v = r.views;
  EXPECT_EQ(count(v, "class=\"panel\""), 2u);
  EXPECT_EQ(count(v, "line plane (device x-y)"), 2u);
  EXPECT_EQ(count(v, "cf. thesis Figs"), 0u);
  EXPECT_EQ(count(v, "VM path: line, L = 50 mm"), 1u);
  for (const char* tag : {"off", "on"}) {
    const auto path = element(v, std::string("path-") + tag);
    ASSERT_EQ(path.at("<name>"), "line") << tag;
    const auto pivot = element(v, std::string("xv-") + tag);  // from the pivot
    ASSERT_FALSE(pivot.empty()) << tag;
    EXPECT_NEAR(number(path, "x1"), number(path, "x2"), 1e-9) << tag;
    EXPECT_NEAR(number(path, "x1"), number(pivot, "x1"), 0.011) << tag;
    EXPECT_GT(std::abs(number(path, "y1") - number(path, "y2")), 300.0) << tag;
  }
}

// The circle's views: the arrow starts at p and is kPlotForceMmPerN x F
// (its in-plane part), read back in mm through the path circle's radius.
TEST(PlotSvgTest, ForceArrowIsTheForceTimesTheScale) {
  const CaseRun& r = run(2);
  const VmParams& vm = r.loop->controller_params().vm;
  for (const auto& [tag, segment] : std::vector<std::pair<std::string, std::string>>{
           {"off", "off_out_misaligned"}, {"on", "on_misaligned_a"}}) {
    SCOPED_TRACE(tag);
    const TickRecord& row = snapshot_row(r, segment);
    const auto path = element(r.views, "path-" + tag);
    const auto shaft = element(r.views, "force-" + tag);
    ASSERT_FALSE(path.empty());
    ASSERT_FALSE(shaft.empty());
    const double mm = number(path, "r") / vm.length_mm;  // px per mm
    const double cx = number(path, "cx"), cy = number(path, "cy");
    const double x1 = number(shaft, "x1"), y1 = number(shaft, "y1");
    const double x2 = number(shaft, "x2"), y2 = number(shaft, "y2");
    const Vec3 p = row.out.p_rm_mm - vm.pivot_mm;
    const Vec3 F = row.out.force_device_N;
    const double tol = 0.02;  // mm: the 0.01 px print rounding, twice
    EXPECT_NEAR((x1 - cx) / mm, p.x(), tol);
    EXPECT_NEAR((cy - y1) / mm, p.y(), tol);
    EXPECT_NEAR((x2 - x1) / mm, kPlotForceMmPerN * F.x(), tol);
    EXPECT_NEAR((y1 - y2) / mm, kPlotForceMmPerN * F.y(), tol);
    EXPECT_NEAR(std::hypot(x2 - x1, y2 - y1) / mm,
                kPlotForceMmPerN * std::hypot(F.x(), F.y()), tol);
    if (tag == "off") {
      // held off the path, the VM pulls: the check is not on a zero arrow
      EXPECT_GT(F.norm(), 0.3);
      EXPECT_GT(row.d_path_mm, 1.0);
    }
  }
}

// The sphere's three projections hold each component of F twice: the
// arrows' lengths give back |F| x the scale.
TEST(PlotSvgTest, SphereProjectionsRecoverTheForce) {
  const CaseRun& r = run(5);
  const VmParams& vm = r.loop->controller_params().vm;
  for (const auto& [snap, segment] : std::vector<std::pair<std::string, std::string>>{
           {"off", "off_out_misaligned"}, {"on", "on_misaligned_a"}}) {
    SCOPED_TRACE(snap);
    const Vec3 F = kPlotForceMmPerN * snapshot_row(r, segment).out.force_device_N;
    double sum_sq = 0.0;
    std::map<std::string, double> expected = {{"xy", std::hypot(F.x(), F.y())},
                                              {"xz", std::hypot(F.x(), F.z())},
                                              {"zy", std::hypot(F.z(), F.y())}};
    for (const auto& [view, want] : expected) {
      const auto path = element(r.views, "path-" + snap + "-" + view);
      const auto shaft = element(r.views, "force-" + snap + "-" + view);
      const double mm = number(path, "r") / vm.length_mm;
      const double len = std::hypot(number(shaft, "x2") - number(shaft, "x1"),
                                    number(shaft, "y2") - number(shaft, "y1")) / mm;
      EXPECT_NEAR(len, want, 0.02) << view;
      sum_sq += len * len;
    }
    EXPECT_NEAR(std::sqrt(0.5 * sum_sq), F.norm(), 0.03);
    if (snap == "off") {
      EXPECT_GT(F.norm(), 3.0);  // mm: a visible arrow
    }
  }
}

// Three panels, eleven series, each at most kPlotMaxPoints + 1 points (a
// 20 s run has 20000 ticks), the segments named, the axes labelled.
TEST(PlotSvgTest, HistoryPolylinesAreDecimatedAndLabelled) {
  for (int n : {2, 5}) {
    const CaseRun& r = run(n);
    SCOPED_TRACE(n);
    ASSERT_EQ(r.rows.size(), 20000u);
    // (found by hand: std::regex recurses per character on long strings)
    std::size_t lines = 0, most = 0;
    for (std::size_t at = r.history.find("<polyline"); at != std::string::npos;
         at = r.history.find("<polyline", at + 1)) {
      const std::size_t from = r.history.find(" points=\"", at) + 9;
      const std::string pts = r.history.substr(from, r.history.find('"', from) - from);
      const std::size_t k = count(pts, " ") + 1;
      EXPECT_LE(k, kPlotMaxPoints + 1);
      EXPECT_EQ(count(pts, ","), k);
      most = std::max(most, k);
      ++lines;
    }
    EXPECT_EQ(lines, 11u);
    EXPECT_GE(most, kPlotMaxPoints / 2);
    EXPECT_EQ(count(r.history, "class=\"history\""), 3u);
    for (const ScriptSegment& s : r.loop->script().segments()) {
      EXPECT_NE(r.history.find(">" + s.name + "</text>"), std::string::npos) << s.name;
    }
    for (const char* label : {">t (s)<", "p - X(theta_V) (mm)", "p - X(theta_R) (mm)",
                              "force F (N)", ">F_x<", ">|F|<"}) {
      EXPECT_NE(r.history.find(label), std::string::npos) << label;
    }
  }
}

}  // namespace
}  // namespace vmh::thesis
