// output/svg_chart.cc: the chart is well-formed SVG, and its pixels say what
// the data says. Points are read back from the series' <polyline> and
// <circle> elements and mapped against the plot area's frame
// (<rect class="plot-area">): a point on an axis limit lands on the frame's
// edge, a linear axis is linear, a log axis spaces decades equally, dropped
// points are counted in <desc>.
//
// With VMH_SVG_CHART_DIR set, the charts are also written there for a look.
#include "output/svg_chart.h"
#include "output/svg_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/svg_check.h"

namespace vmh::output {
namespace {

using vmh::testing::count;
using vmh::testing::tag_problems;

using Pt = std::pair<double, double>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPx = 0.006;  // the document prints pixels to 0.01

void save(const std::string& name, const std::string& doc) {
  if (const char* dir = std::getenv("VMH_SVG_CHART_DIR")) {
    std::ofstream(std::string(dir) + "/" + name + ".svg") << doc;
  }
}

// the attributes of the first element <name ... class="cls" ...>
std::map<std::string, std::string> attributes(const std::string& element) {
  std::map<std::string, std::string> a;
  static const std::regex kAttr(R"re(([A-Za-z0-9:-]+)="([^"]*)")re");
  for (std::sregex_iterator m(element.begin(), element.end(), kAttr), end;
       m != end; ++m) {
    a[(*m)[1].str()] = (*m)[2].str();
  }
  return a;
}

struct Frame {
  double x = kNaN, y = kNaN, w = kNaN, h = kNaN;
  double left() const { return x; }
  double right() const { return x + w; }
  double top() const { return y; }
  double bottom() const { return y + h; }
};

Frame plot_area(const std::string& doc) {
  const std::size_t at = doc.find("class=\"plot-area\"");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no plot-area";
    return {};
  }
  const auto a = attributes(doc.substr(doc.rfind('<', at), doc.find('>', at) - doc.rfind('<', at)));
  return {std::stod(a.at("x")), std::stod(a.at("y")), std::stod(a.at("width")),
          std::stod(a.at("height"))};
}

// the text of <g class="series" id="series-N"> ... </g>
std::string series_group(const std::string& doc, int n) {
  const std::string head = "<g class=\"series\" id=\"series-" + std::to_string(n) + "\"";
  const std::size_t at = doc.find(head);
  if (at == std::string::npos) return "";
  return doc.substr(at, doc.find("</g>", at) - at);
}

std::vector<Pt> markers(const std::string& group) {
  std::vector<Pt> pts;
  for (std::size_t at = group.find("<circle"); at != std::string::npos;
       at = group.find("<circle", at + 1)) {
    const auto a = attributes(group.substr(at, group.find('>', at) - at));
    pts.emplace_back(std::stod(a.at("cx")), std::stod(a.at("cy")));
  }
  return pts;
}

// the polyline's points; empty if there is none
std::vector<Pt> polyline(const std::string& group) {
  std::vector<Pt> pts;
  const std::size_t at = group.find("<polyline");
  if (at == std::string::npos) return pts;
  const auto a = attributes(group.substr(at, group.find('>', at) - at));
  std::istringstream in(a.at("points"));
  std::string item;
  while (in >> item) {
    const std::size_t comma = item.find(',');
    pts.emplace_back(std::stod(item.substr(0, comma)),
                     std::stod(item.substr(comma + 1)));
  }
  return pts;
}

std::string desc(const std::string& doc) {
  const std::size_t a = doc.find("<desc>") + 6;
  return doc.substr(a, doc.find("</desc>", a) - a);
}

ChartSeries series(std::vector<double> x, std::vector<double> y,
                   std::string label = "s") {
  ChartSeries s;
  s.label = std::move(label);
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

// Fixed linear axes: the corners of the range land on the frame's corners,
// the middle in its middle, y up.
TEST(SvgChartTest, LinearAxisLimitsLandOnTheFrameEdges) {
  Chart c;
  c.title = "linear";
  c.x = {"x (m)", false, 0.0, 10.0};
  c.y = {"y (N)", false, -5.0, 5.0};
  c.series.push_back(series({0.0, 10.0, 5.0, 2.5}, {-5.0, 5.0, 0.0, 2.5}));
  const std::string doc = chart_svg(c);
  save("linear", doc);
  EXPECT_EQ(tag_problems(doc), "");
  const Frame f = plot_area(doc);
  ASSERT_GT(f.w, 100.0);
  ASSERT_GT(f.h, 100.0);
  const std::vector<Pt> m = markers(series_group(doc, 0));
  ASSERT_EQ(m.size(), 4u);
  EXPECT_NEAR(m[0].first, f.left(), kPx);     // x = min: the left edge
  EXPECT_NEAR(m[0].second, f.bottom(), kPx);  // y = min: the bottom edge
  EXPECT_NEAR(m[1].first, f.right(), kPx);
  EXPECT_NEAR(m[1].second, f.top(), kPx);
  EXPECT_NEAR(m[2].first, f.left() + 0.5 * f.w, kPx);
  EXPECT_NEAR(m[2].second, f.top() + 0.5 * f.h, kPx);
  EXPECT_NEAR(m[3].first, f.left() + 0.25 * f.w, kPx);
  EXPECT_NEAR(m[3].second, f.top() + 0.25 * f.h, kPx);
  // the polyline goes through the same pixels, in the data's order
  EXPECT_EQ(polyline(series_group(doc, 0)), m);
  // labels, ticks
  EXPECT_EQ(count(doc, "class=\"axis-label\""), 2u);
  EXPECT_NE(doc.find(">x (m)</text>"), std::string::npos);
  EXPECT_NE(doc.find(">y (N)</text>"), std::string::npos);
  EXPECT_NE(doc.find(">linear</text>"), std::string::npos);
  for (const char* tick : {">0</text>", ">10</text>", ">-4</text>", ">4</text>"}) {
    EXPECT_NE(doc.find(tick), std::string::npos) << tick;
  }
  EXPECT_EQ(doc.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" class=\"chart\"", 0), 0u);
}

// Log axes from the data: whole decades, 10 and 100 one decade apart, as far
// apart in pixels as 100 and 1000, and a decade's ticks labelled 10^k.
TEST(SvgChartTest, LogAxisSpacesDecadesEqually) {
  Chart c;
  c.x = {"wall time (s)", true};
  c.y = {"error (m)", true};
  c.series.push_back(series({10.0, 100.0, 1000.0, 31.622776601683793},
                            {1e-3, 1e-5, 1e-7, 1e-4}));
  const std::string doc = chart_svg(c);
  save("loglog", doc);
  EXPECT_EQ(tag_problems(doc), "");
  const Frame f = plot_area(doc);
  const std::vector<Pt> m = markers(series_group(doc, 0));
  ASSERT_EQ(m.size(), 4u);
  // the data span whole decades here, so the axes are exactly 10..1000 and
  // 1e-7..1e-3
  EXPECT_NEAR(m[0].first, f.left(), kPx);
  EXPECT_NEAR(m[2].first, f.right(), kPx);
  EXPECT_NEAR(m[0].second, f.top(), kPx);
  EXPECT_NEAR(m[2].second, f.bottom(), kPx);
  const double decade_x = m[1].first - m[0].first;
  EXPECT_NEAR(decade_x, 0.5 * f.w, kPx);
  EXPECT_NEAR(m[2].first - m[1].first, decade_x, 2 * kPx);
  EXPECT_NEAR(m[1].second - m[0].second, 0.5 * f.h, kPx);  // two decades down
  // sqrt(1000) is half a decade above 10; 1e-4 three quarters of the way
  EXPECT_NEAR(m[3].first, f.left() + 0.25 * f.w, kPx);
  EXPECT_NEAR(m[3].second, f.top() + 0.25 * f.h, kPx);
  // decade ticks: 10^1, 10^2, 10^3 on x; 10^-7 .. 10^-3 on y
  for (const char* e : {">1<", ">2<", ">3<", ">-7<", ">-5<", ">-3<"}) {
    EXPECT_NE(doc.find(std::string("10<tspan dy=\"-5\" font-size=\"8\"") + e),
              std::string::npos)
        << e;
  }
}

// Data not on whole decades: the log axis widens to the decades around
// them; an axis from data on a linear axis is padded, so every point is
// inside the frame and none on its edge.
TEST(SvgChartTest, RangesFromTheData) {
  Chart c;
  c.x = {"x", true};
  c.y = {"y", false};
  c.series.push_back(series({2.0, 50.0}, {3.0, 7.0}));
  const std::string doc = chart_svg(c);
  const Frame f = plot_area(doc);
  const std::vector<Pt> m = markers(series_group(doc, 0));
  ASSERT_EQ(m.size(), 2u);
  // x axis 1..100: log10(2) and log10(50) of the two decades
  EXPECT_NEAR(m[0].first, f.left() + std::log10(2.0) / 2.0 * f.w, kPx);
  EXPECT_NEAR(m[1].first, f.left() + std::log10(50.0) / 2.0 * f.w, kPx);
  // y axis 3 - 0.2 .. 7 + 0.2 (5% of the span each side)
  EXPECT_NEAR(m[0].second, f.bottom() - 0.2 / 4.4 * f.h, kPx);
  EXPECT_NEAR(m[1].second, f.top() + 0.2 / 4.4 * f.h, kPx);

  // one value only, and no data at all: still a frame with finite numbers
  Chart one;
  one.series.push_back(series({5.0}, {0.0}));
  const std::string d1 = chart_svg(one);
  EXPECT_EQ(tag_problems(d1), "");
  const Frame f1 = plot_area(d1);
  const std::vector<Pt> m1 = markers(series_group(d1, 0));
  ASSERT_EQ(m1.size(), 1u);
  EXPECT_NEAR(m1[0].first, f1.left() + 0.5 * f1.w, kPx);
  EXPECT_NEAR(m1[0].second, f1.top() + 0.5 * f1.h, kPx);
  EXPECT_TRUE(polyline(series_group(d1, 0)).empty());  // one point: no line
  Chart none;
  none.x.log = true;
  const std::string d0 = chart_svg(none);
  EXPECT_EQ(tag_problems(d0), "");
  EXPECT_EQ(d0.find("nan"), std::string::npos);
  EXPECT_EQ(d0.find("inf"), std::string::npos);
}

// Non-finite points are dropped everywhere, non-positive ones on a log
// axis; the markers are the points left, and <desc> counts the rest.
TEST(SvgChartTest, DropsPointsItCannotDrawAndSaysHowMany) {
  Chart c;
  c.x = {"x", false, 0.0, 4.0};
  c.y = {"y", true, 1.0, 1000.0};
  c.series.push_back(series({0.0, 1.0, 2.0, 3.0, 4.0, kNaN},
                            {10.0, kNaN, -1.0, 0.0, 100.0, 5.0}, "a"));
  c.series.push_back(series({0.5, kInf, 1.5}, {2.0, 3.0, 4.0}, "b"));
  const std::string doc = chart_svg(c);
  EXPECT_EQ(tag_problems(doc), "");
  EXPECT_NE(desc(doc).find("4 points drawn"), std::string::npos) << desc(doc);
  EXPECT_NE(desc(doc).find("3 non-finite point(s)"), std::string::npos) << desc(doc);
  EXPECT_NE(desc(doc).find("2 non-positive point(s)"), std::string::npos) << desc(doc);
  const Frame f = plot_area(doc);
  const std::vector<Pt> a = markers(series_group(doc, 0));
  ASSERT_EQ(a.size(), 2u);  // (0, 10) and (4, 100)
  EXPECT_NEAR(a[0].first, f.left(), kPx);
  EXPECT_NEAR(a[0].second, f.bottom() - f.h / 3.0, kPx);
  EXPECT_NEAR(a[1].first, f.right(), kPx);
  EXPECT_NEAR(a[1].second, f.bottom() - 2.0 * f.h / 3.0, kPx);
  EXPECT_EQ(polyline(series_group(doc, 0)), a);
  EXPECT_EQ(markers(series_group(doc, 1)).size(), 2u);
  EXPECT_EQ(doc.find("nan"), std::string::npos);
  EXPECT_EQ(doc.find("inf"), std::string::npos);
  // every circle in the document is a marker of a series
  EXPECT_EQ(count(doc, "<circle"), 4u);
}

// A series' look (SeriesLook): its own dash pattern, line width, marker
// radius and hollow markers, in the series and in its legend sample; a
// series without a look keeps the defaults.
TEST(SvgChartTest, SeriesLooksForCurvesThatCoincide) {
  Chart c;
  c.x = {"h (s)", true};
  c.y = {"error (mm)", true};
  ChartSeries under = series({1e-3, 1e-2}, {1e-2, 1e-1}, "under");
  ChartSeries over = series({1e-3, 1e-2}, {1e-2, 1e-1}, "over");
  ChartSeries plain = series({1e-3, 1e-2}, {1e-3, 1e-2}, "plain");
  c.series = {under, over, plain};
  c.looks.resize(2);
  c.looks[0].line_width = 3.5;
  c.looks[0].marker_radius = 5.0;
  c.looks[1].dash = "2 2";
  c.looks[1].hollow = true;
  const std::string doc = chart_svg(c);
  save("looks", doc);
  EXPECT_EQ(tag_problems(doc), "");
  const std::string g0 = series_group(doc, 0), g1 = series_group(doc, 1);
  const std::string g2 = series_group(doc, 2);
  EXPECT_NE(g0.find("stroke-width=\"3.5\""), std::string::npos);
  EXPECT_NE(g0.find("r=\"5.00\""), std::string::npos);
  EXPECT_EQ(g0.find("stroke-dasharray"), std::string::npos);
  EXPECT_NE(g1.find("stroke-dasharray=\"2 2\""), std::string::npos);
  // rings: no fill, the series' colour as stroke
  EXPECT_EQ(count(g1, "<circle"), 2u);
  EXPECT_EQ(count(g1, "fill=\"none\""), 3u);  // the polyline and 2 rings
  EXPECT_NE(g2.find("stroke-width=\"1.5\""), std::string::npos);
  EXPECT_NE(g2.find("r=\"3.00\""), std::string::npos);
  // the legend shows the same: the wide line, the dotted one, a ring
  const std::size_t legend = doc.find("<g class=\"legend\">");
  ASSERT_NE(legend, std::string::npos);
  const std::string lg = doc.substr(legend, doc.find("</g>", legend) - legend);
  EXPECT_NE(lg.find("stroke-width=\"3.5\""), std::string::npos);
  EXPECT_NE(lg.find("stroke-dasharray=\"2 2\""), std::string::npos);
  EXPECT_EQ(count(lg, "fill=\"none\""), 1u);
  // the plot's clip path is wider than the plot area by the largest marker
  // and a pixel, so that a large dot on an axis limit shows whole
  const std::size_t clip = doc.find("<clipPath");
  ASSERT_NE(clip, std::string::npos);
  const std::size_t rect = doc.find("<rect", clip);
  const auto a = attributes(doc.substr(rect, doc.find('>', rect) - rect));
  EXPECT_NEAR(std::stod(a.at("x")), plot_area(doc).x - 6.0, 1e-9);
}

// Each series in its own group, in order: polyline and/or markers as asked,
// dashed when asked, a palette colour unless one is given; the legend names
// them.
TEST(SvgChartTest, SeriesStylesColoursAndLegend) {
  Chart c;
  c.x = {"B (N s/m)"};
  c.y = {"K_crit (N/m)"};
  ChartSeries sim = series({0, 1, 2}, {1, 2, 3}, "simulated");
  sim.line = false;
  ChartSeries theory = series({0, 1, 2}, {1.1, 2.1, 3.1}, "2(b+B)/T");
  theory.markers = false;
  theory.dashed = true;
  ChartSeries given = series({0, 2}, {0, 1}, "given <colour> & more");
  given.color = "rgb(1,2,3)";
  ChartSeries unnamed = series({0, 2}, {1, 0}, "");
  c.series = {sim, theory, given, unnamed};
  const std::string doc = chart_svg(c);
  save("styles", doc);
  EXPECT_EQ(tag_problems(doc), "");
  EXPECT_EQ(count(doc, "class=\"series\""), 4u);
  const std::string g0 = series_group(doc, 0), g1 = series_group(doc, 1);
  const std::string g2 = series_group(doc, 2), g3 = series_group(doc, 3);
  EXPECT_TRUE(polyline(g0).empty());
  EXPECT_EQ(markers(g0).size(), 3u);
  EXPECT_EQ(polyline(g1).size(), 3u);
  EXPECT_TRUE(markers(g1).empty());
  EXPECT_NE(g1.find("stroke-dasharray"), std::string::npos);
  EXPECT_EQ(g0.find("stroke-dasharray"), std::string::npos);
  EXPECT_EQ(g2.find("stroke-dasharray"), std::string::npos);
  // palette: the first, second and third palette colours go to the series
  // without one; the given colour is used as given
  EXPECT_NE(g0.find("fill=\"#1f77b4\""), std::string::npos);
  EXPECT_NE(g1.find("stroke=\"#ff7f0e\""), std::string::npos);
  EXPECT_NE(g2.find("rgb(1,2,3)"), std::string::npos);
  EXPECT_NE(g3.find("#2ca02c"), std::string::npos);
  // legend: the labelled series only, text escaped
  const std::size_t legend = doc.find("<g class=\"legend\">");
  ASSERT_NE(legend, std::string::npos);
  const std::string lg = doc.substr(legend, doc.find("</g>", legend) - legend);
  EXPECT_EQ(count(lg, "<text"), 3u);
  EXPECT_NE(lg.find(">simulated</text>"), std::string::npos);
  EXPECT_NE(lg.find(">2(b+B)/T</text>"), std::string::npos);
  EXPECT_NE(lg.find(">given &lt;colour&gt; &amp; more</text>"), std::string::npos);
  EXPECT_NE(lg.find("stroke-dasharray"), std::string::npos);
  // the legend is outside the plot area, to its right
  const Frame f = plot_area(doc);
  const auto first_text = attributes(lg.substr(lg.find("<text"), lg.find('>', lg.find("<text")) - lg.find("<text")));
  EXPECT_GT(std::stod(first_text.at("x")), f.right());
  EXPECT_LT(std::stod(first_text.at("x")), c.width_px);
}

// More series than colours: the palette wraps around.
TEST(SvgChartTest, PaletteWraps) {
  Chart c;
  for (int i = 0; i < 11; ++i) c.series.push_back(series({0, 1}, {0, 1.0 * i}));
  const std::string doc = chart_svg(c);
  EXPECT_NE(series_group(doc, 10).find("#1f77b4"), std::string::npos);
  EXPECT_NE(series_group(doc, 9).find("#17becf"), std::string::npos);
}

TEST(SvgChartTest, MismatchedLengthsThrow) {
  Chart c;
  c.series.push_back(series({0, 1}, {0, 1}));
  c.series.push_back(series({0, 1, 2}, {0, 1}, "bad"));
  try {
    chart_svg(c);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("series 1"), std::string::npos) << e.what();
  }
}

// A limit a log axis cannot use is ignored (the data's decades are used)
// and said so.
TEST(SvgChartTest, UnusableLimitsAreIgnoredAndNoted) {
  Chart c;
  c.x = {"x", true, -1.0, 100.0};
  c.series.push_back(series({1.0, 10.0}, {0.0, 1.0}));
  const std::string doc = chart_svg(c);
  EXPECT_NE(desc(doc).find("x axis minimum -1 was ignored"), std::string::npos) << desc(doc);
  const Frame f = plot_area(doc);
  const std::vector<Pt> m = markers(series_group(doc, 0));
  ASSERT_EQ(m.size(), 2u);
  EXPECT_NEAR(m[0].first, f.left(), kPx);  // 1 .. 100
  EXPECT_NEAR(m[1].first, f.left() + 0.5 * f.w, kPx);
}

// A band shades its x interval over the plot area's whole height, under the
// series; a subtitle lowers the plot area by its row and carries its colour.
TEST(SvgChartTest, BandsAndSubtitle) {
  Chart plain;
  plain.x = {"t (s)", false, 0.0, 10.0};
  plain.y = {"E (mJ)", false, -1.0, 1.0};
  plain.series.push_back(series({0, 10}, {-1, 1}));
  Chart c = plain;
  c.subtitle = "limit_cycle & more";
  c.subtitle_color = "#e65100";
  c.bands.push_back({9.0, 8.0});  // either order
  c.bands.push_back({-5.0, 1.0});  // clamped to the plot area
  const std::string doc = chart_svg(c);
  save("bands", doc);
  EXPECT_EQ(tag_problems(doc), "");
  const Frame f = plot_area(doc), f0 = plot_area(chart_svg(plain));
  EXPECT_NEAR(f.top(), f0.top() + 14.0, kPx);
  EXPECT_NEAR(f.bottom(), f0.bottom(), kPx);
  EXPECT_NE(doc.find("fill=\"#e65100\">limit_cycle &amp; more</text>"),
            std::string::npos);
  const std::size_t at = doc.find("<g class=\"bands\"");
  ASSERT_NE(at, std::string::npos);
  EXPECT_LT(at, doc.find("class=\"series\""));
  const std::string g = doc.substr(at, doc.find("</g>", at) - at);
  ASSERT_EQ(count(g, "<rect"), 2u);
  const std::size_t r1 = g.find("<rect"), r2 = g.find("<rect", r1 + 1);
  const auto a = attributes(g.substr(r1, g.find('>', r1) - r1));
  const auto b = attributes(g.substr(r2, g.find('>', r2) - r2));
  EXPECT_NEAR(std::stod(a.at("x")), f.left() + 0.8 * f.w, kPx);
  EXPECT_NEAR(std::stod(a.at("width")), 0.1 * f.w, kPx);
  EXPECT_NEAR(std::stod(a.at("y")), f.top(), kPx);
  EXPECT_NEAR(std::stod(a.at("height")), f.h, kPx);
  EXPECT_NEAR(std::stod(b.at("x")), f.left(), kPx);
  EXPECT_NEAR(std::stod(b.at("width")), 0.1 * f.w, kPx);
  // no subtitle, no band: no trace of either
  const std::string doc0 = chart_svg(plain);
  EXPECT_EQ(doc0.find("subtitle"), std::string::npos);
  EXPECT_EQ(doc0.find("bands"), std::string::npos);
}

// Panels of a grid: one document, each panel a nested chart at its cell,
// with ids of its own, laid out row by row under the title and notes.
TEST(SvgChartTest, GridOfPanels) {
  ChartGrid grid;
  grid.title = "energy <per> scenario";
  grid.notes = {"first note", "second note"};
  grid.columns = 2;
  for (int i = 0; i < 3; ++i) {
    Chart c;
    c.title = "panel " + std::to_string(i);
    c.width_px = 300;
    c.height_px = 200;
    c.series.push_back(series({0, 1}, {0, 1.0 + i}, ""));
    grid.panels.push_back(c);
  }
  const std::string doc = chart_grid_svg(grid);
  save("grid", doc);
  EXPECT_EQ(tag_problems(doc), "");
  EXPECT_EQ(doc.rfind("<svg xmlns", 0), 0u);
  EXPECT_NE(doc.find("class=\"chart-grid\" width=\"600.00\""), std::string::npos);
  EXPECT_NE(doc.find(">energy &lt;per&gt; scenario</text>"), std::string::npos);
  EXPECT_EQ(count(doc, "class=\"note\""), 2u);
  EXPECT_EQ(count(doc, "<svg class=\"chart\""), 3u);
  // ids are the panel's own: no two alike
  for (int k = 0; k < 3; ++k) {
    const std::string id = "panel-" + std::to_string(k);
    EXPECT_EQ(count(doc, "id=\"" + id + "\""), 1u) << id;
    EXPECT_EQ(count(doc, "id=\"" + id + "-plot-clip\""), 1u) << id;
    EXPECT_EQ(count(doc, "url(#" + id + "-plot-clip)"), 1u) << id;
    EXPECT_EQ(count(doc, "id=\"" + id + "-series-0\""), 1u) << id;
  }
  EXPECT_EQ(doc.find("id=\"series-0\""), std::string::npos);
  // cells: the third panel starts the second row, one panel height lower
  const auto cell = [&](int k) {
    const std::size_t at = doc.find("id=\"panel-" + std::to_string(k) + "\"");
    const std::size_t lt = doc.rfind('<', at);
    return attributes(doc.substr(lt, doc.find('>', at) - lt));
  };
  EXPECT_DOUBLE_EQ(std::stod(cell(1).at("x")), 300.0);
  EXPECT_DOUBLE_EQ(std::stod(cell(2).at("x")), 0.0);
  EXPECT_DOUBLE_EQ(std::stod(cell(2).at("y")) - std::stod(cell(0).at("y")), 200.0);
  EXPECT_GT(std::stod(cell(0).at("y")), 2 * 18.0);  // below the notes
  // a bad panel is named
  grid.panels[1].series.push_back(series({0}, {0, 1}, "bad"));
  try {
    chart_grid_svg(grid);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("panel 1"), std::string::npos) << e.what();
  }
}

// A pixel coordinate is printf's "%.2f" (std::to_chars writes it), with
// -0.00 written 0.00 and a non-finite value drawn at 0: checked against
// snprintf over the magnitudes a figure has, ties of the second decimal,
// and the extremes.
TEST(SvgText, PixelCoordinatesArePrintfsTwoDecimals) {
  std::vector<double> values = {0.0, -0.0, 0.005, -0.005, 0.015, 2.675, 1.005,
                                -0.004, 1e15, -1e300,
                                std::numeric_limits<double>::max(),
                                -std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::denorm_min()};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(-5000.0, 5000.0);
  for (int i = 0; i < 100000; ++i) {
    const double v = coord(rng);
    values.push_back(i % 4 ? v : std::round(v * 200.0) / 200.0);  // ties
  }
  int mismatches = 0;
  for (double v : values) {
    char want[400];
    std::snprintf(want, sizeof want, "%.2f", v);
    std::string w = want;
    if (w == "-0.00") w = "0.00";
    if (svg::px(v) != w && ++mismatches <= 5) {
      ADD_FAILURE() << "px wrote " << svg::px(v) << ", printf writes " << w;
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(svg::px(std::nan("")), "0.00");
  EXPECT_EQ(svg::px(-std::numeric_limits<double>::infinity()), "0.00");
}

}  // namespace
}  // namespace vmh::output
