#include "output/svg_chart.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "output/svg_text.h"

namespace vmh::output {
namespace {

using svg::attr;
using svg::escape;
using svg::format;
using svg::nice_step;
using svg::px;

// ---------------------------------------------------------------- text

// a number a reader reads (tick labels): plain from 0.001 to 1e7
// ("150000", not "1.5e+05"), else in e-notation
std::string num(double v) {
  const double a = std::abs(v);
  std::string s = format(a == 0.0 || (a >= 1e-3 && a < 1e7) ? "%.7g" : "%.4g", v);
  if (s == "-0") s = "0";
  return s;
}

// Tableau 10: distinct on white, and in the usual order of matplotlib
const char* const kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                                "#bcbd22", "#17becf"};
constexpr std::size_t kPaletteSize = sizeof kPalette / sizeof kPalette[0];

// ---------------------------------------------------------------- layout

constexpr double kMarginLeft = 72.0;    // y tick numbers and the y label
constexpr double kMarginRight = 16.0;
constexpr double kMarginTop = 34.0;     // the title
constexpr double kMarginBottom = 50.0;  // x tick numbers and the x label
constexpr double kLegendGap = 12.0;     // plot area to legend
constexpr double kLegendRow = 17.0;     // px per legend entry
constexpr double kLegendSample = 26.0;  // the line/marker sample's width
constexpr double kCharWidth = 6.4;      // a rough average at font-size 11
constexpr double kMarkerRadius = 3.0;
constexpr double kMinPlot = 40.0;       // the plot area never shrinks below

// ---------------------------------------------------------------- axes

// One axis: the data range it shows and the map to pixels along it.
struct Scale {
  bool log = false;
  double lo = 0.0, hi = 1.0;      // data units (both > 0 on a log axis)
  double px_lo = 0.0, px_hi = 1.0;  // pixels of lo and hi

  double to_px(double v) const {
    const double a = log ? std::log10(lo) : lo;
    const double b = log ? std::log10(hi) : hi;
    const double u = log ? std::log10(v) : v;
    return px_lo + (u - a) / (b - a) * (px_hi - px_lo);
  }
};

struct Tick {
  double value;
  bool major;  // labelled, with a stronger grid line
};

std::vector<Tick> linear_ticks(double lo, double hi) {
  const double step = nice_step(hi - lo, 6.0);
  std::vector<Tick> t;
  const long k0 = static_cast<long>(std::ceil(lo / step - 1e-9));
  const long k1 = static_cast<long>(std::floor(hi / step + 1e-9));
  for (long k = k0; k <= k1; ++k) {
    double v = static_cast<double>(k) * step;
    if (std::abs(v) < 1e-12 * step) v = 0.0;
    t.push_back({v, true});
  }
  return t;
}

// a tick at each decade; minor ticks at 2..9 x 10^k when the axis spans a
// few decades only. With fewer than two decades inside the range the minor
// ticks are labelled too, or the axis would carry one number or none.
std::vector<Tick> log_ticks(double lo, double hi) {
  const double a = std::log10(lo), b = std::log10(hi);
  const long e0 = static_cast<long>(std::floor(a + 1e-9));
  const long e1 = static_cast<long>(std::ceil(b - 1e-9));
  const long decades = e1 - e0;
  // label every n-th decade so that at most about ten numbers show
  const long every = std::max(1L, (decades + 9) / 10);
  std::vector<Tick> t;
  int majors_inside = 0;
  for (long e = e0; e <= e1; ++e) {
    const double v = std::pow(10.0, static_cast<double>(e));
    if (v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9)) ++majors_inside;
  }
  const bool minor = decades <= 6;
  const bool label_minor = majors_inside < 2;
  for (long e = e0; e <= e1; ++e) {
    const double d = std::pow(10.0, static_cast<double>(e));
    if (d >= lo * (1.0 - 1e-9) && d <= hi * (1.0 + 1e-9)) {
      t.push_back({d, (e % every) == 0});
    }
    if (!minor) continue;
    for (int m = 2; m <= 9; ++m) {
      const double v = m * d;
      if (v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9)) {
        t.push_back({v, label_minor});
      }
    }
  }
  return t;
}

// The range an axis shows: the one given, else from the data (`data_lo`,
// `data_hi`, empty when data_lo > data_hi): padded by 5% of the span on a
// linear axis, widened to whole decades on a log axis. A limit the axis
// cannot use (non-finite, <= 0 on a log axis, or min >= max) is ignored and
// noted in `notes`.
std::pair<double, double> axis_range(const ChartAxis& axis, double data_lo,
                                     double data_hi, const char* name,
                                     std::string* notes) {
  double lo = axis.min, hi = axis.max;
  auto usable = [&](double v) {
    return std::isfinite(v) && (!axis.log || v > 0.0);
  };
  if (!std::isnan(lo) && !usable(lo)) {
    *notes += std::string(" The ") + name + " axis minimum " + num(lo) +
              " was ignored" + (axis.log ? " (log axis)." : ".");
    lo = std::nan("");
  }
  if (!std::isnan(hi) && !usable(hi)) {
    *notes += std::string(" The ") + name + " axis maximum " + num(hi) +
              " was ignored" + (axis.log ? " (log axis)." : ".");
    hi = std::nan("");
  }
  if (!std::isnan(lo) && !std::isnan(hi) && !(lo < hi)) {
    *notes += std::string(" The ") + name + " axis limits " + num(lo) +
              " >= " + num(hi) + " were ignored.";
    lo = hi = std::nan("");
  }
  const bool have_data = data_lo <= data_hi;
  if (axis.log) {
    if (std::isnan(lo)) {
      lo = have_data ? std::pow(10.0, std::floor(std::log10(data_lo) + 1e-9))
                     : 1.0;
      if (!std::isnan(hi) && !(lo < hi)) {
        lo = std::pow(10.0, std::floor(std::log10(hi)) - 1.0);
      }
    }
    if (std::isnan(hi)) {
      hi = have_data ? std::pow(10.0, std::ceil(std::log10(data_hi) - 1e-9))
                     : 10.0 * lo;
      if (!(hi > lo)) hi = std::pow(10.0, std::floor(std::log10(lo) + 1e-9) + 1.0);
    }
    if (!(hi > lo)) hi = 10.0 * lo;
    return {lo, hi};
  }
  const bool free_lo = std::isnan(lo), free_hi = std::isnan(hi);
  if (free_lo || free_hi) {
    double a = have_data ? data_lo : 0.0, b = have_data ? data_hi : 1.0;
    if (!free_lo) a = std::max(a, lo);
    if (!free_hi) b = std::min(b, hi);
    if (!(b > a)) {  // a single value, or the data outside the given limit
      const double c = !free_lo ? lo : !free_hi ? hi : a;
      const double half = c == 0.0 ? 1.0 : 0.05 * std::abs(c);
      a = c - half;
      b = c + half;
    }
    const double pad = 0.05 * (b - a);
    if (free_lo) lo = a - pad;
    if (free_hi) hi = b + pad;
    if (!(hi > lo)) {
      if (free_lo) lo = hi - 1.0;
      else hi = lo + 1.0;
    }
  }
  return {lo, hi};
}

// a tick's number: 10^k (as a superscript) for a decade on a log axis
std::string tick_text(double v, bool log_axis) {
  if (log_axis) {
    const double e = std::log10(v);
    if (std::abs(e - std::round(e)) < 1e-9) {
      return "10<tspan dy=\"-5\" font-size=\"8\">" +
             num(std::round(e)) + "</tspan>";
    }
  }
  return escape(num(v));
}

// a series' points that can be drawn, in order, and how many were dropped
struct Kept {
  std::vector<std::pair<double, double>> pts;  // data units
  std::size_t non_finite = 0;
  std::size_t non_positive = 0;  // finite but <= 0 on a log axis
};

Kept keep(const ChartSeries& s, bool xlog, bool ylog) {
  Kept k;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const double x = s.x[i], y = s.y[i];
    if (!std::isfinite(x) || !std::isfinite(y)) {
      ++k.non_finite;
    } else if ((xlog && x <= 0.0) || (ylog && y <= 0.0)) {
      ++k.non_positive;
    } else {
      k.pts.emplace_back(x, y);
    }
  }
  return k;
}


// a series' stroke: its colour, width and dash pattern
std::string stroke_attrs(const ChartSeries& s, const SeriesLook& look,
                         const std::string& color) {
  const std::string dash = !look.dash.empty() ? look.dash
                           : s.dashed         ? "6 4"
                                              : "";
  const double w = look.line_width > 0.0 ? look.line_width : 1.5;
  return attr("stroke", color) + attr("stroke-width", format("%g", w)) +
         (dash.empty() ? "" : attr("stroke-dasharray", dash));
}

// a marker's radius and paint: filled, or a ring (hollow)
double marker_radius(const SeriesLook& look) {
  return look.marker_radius > 0.0 ? look.marker_radius : kMarkerRadius;
}
std::string marker_paint(const SeriesLook& look, const std::string& color) {
  return look.hollow ? attr("fill", "none") + attr("stroke", color) +
                        attr("stroke-width", "1.5")
                  : attr("fill", color);
}

// series i's look: the chart's, or the defaults
SeriesLook look_of(const Chart& chart, std::size_t i) {
  return i < chart.looks.size() ? chart.looks[i] : SeriesLook{};
}

// ---------------------------------------------------------------- a chart

constexpr double kSubtitleRow = 14.0;  // the top margin grows by it

// What is drawn, in data units: the series' points, the axes' ranges and
// colours, and what was left out (for the <desc>).
struct Prepared {
  std::vector<Kept> kept;  // one per series
  std::vector<std::string> colors;
  std::size_t non_finite = 0, non_positive = 0, points = 0;
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
  std::string notes;  // axis limits that were ignored
};

void check_lengths(const Chart& chart, const std::string& where) {
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const ChartSeries& s = chart.series[i];
    if (s.x.size() != s.y.size()) {
      throw std::invalid_argument(
          where + ": series " + std::to_string(i) + " ('" + s.label +
          "') has " + std::to_string(s.x.size()) + " x values but " +
          std::to_string(s.y.size()) + " y values");
    }
  }
}

Prepared prepare(const Chart& chart) {
  Prepared p;
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo;
  double ylo = xlo, yhi = -xlo;
  std::size_t next_color = 0;
  for (const ChartSeries& s : chart.series) {
    p.kept.push_back(keep(s, chart.x.log, chart.y.log));
    const Kept& k = p.kept.back();
    p.non_finite += k.non_finite;
    p.non_positive += k.non_positive;
    p.points += k.pts.size();
    for (const auto& [x, y] : k.pts) {
      xlo = std::min(xlo, x);
      xhi = std::max(xhi, x);
      ylo = std::min(ylo, y);
      yhi = std::max(yhi, y);
    }
    // colours: given, or the next of the palette
    p.colors.push_back(s.color.empty() ? kPalette[next_color++ % kPaletteSize]
                                       : s.color);
  }
  std::tie(p.x0, p.x1) = axis_range(chart.x, xlo, xhi, "x", &p.notes);
  std::tie(p.y0, p.y1) = axis_range(chart.y, ylo, yhi, "y", &p.notes);
  return p;
}

// Where things go, in pixels: the plot area, with the legend (series with a
// label) to its right.
struct Layout {
  double W = 1.0, H = 1.0;
  double left = 0.0, top = 0.0, plot_w = 0.0, plot_h = 0.0, bottom = 0.0;
  std::size_t legend_rows = 0;
};

Layout layout(const Chart& chart) {
  Layout l;
  l.W = std::max(chart.width_px, 1);
  l.H = std::max(chart.height_px, 1);
  std::size_t legend_chars = 0;
  for (const ChartSeries& s : chart.series) {
    if (s.label.empty()) continue;
    legend_chars = std::max(legend_chars, s.label.size());
    ++l.legend_rows;
  }
  double legend_w = 0.0;
  if (l.legend_rows > 0) {
    legend_w = std::min(kLegendSample + 8.0 +
                            kCharWidth * static_cast<double>(legend_chars) + 8.0,
                        0.4 * l.W);
  }
  const double margin_top =
      kMarginTop + (chart.subtitle.empty() ? 0.0 : kSubtitleRow);
  l.left = kMarginLeft;
  l.top = margin_top;
  l.plot_w = std::max(kMinPlot, l.W - kMarginLeft - kMarginRight -
                                    (legend_w > 0.0 ? legend_w + kLegendGap : 0.0));
  l.plot_h = std::max(kMinPlot, l.H - margin_top - kMarginBottom);
  l.bottom = l.top + l.plot_h;
  return l;
}

// <title>, <desc>, the white ground, the plot area's clip path and the
// title (and subtitle) as text
std::string head_svg(const Chart& chart, const Prepared& p, const Layout& l,
                     const std::string& id) {
  std::string svg;
  if (!chart.title.empty()) svg += "<title>" + escape(chart.title) + "</title>\n";
  const std::string d = std::to_string(chart.series.size()) + " series, " +
                        std::to_string(p.points) + " points drawn. Dropped: " +
                        std::to_string(p.non_finite) + " non-finite point(s), " +
                        std::to_string(p.non_positive) +
                        " non-positive point(s) on a log axis.";
  svg += "<desc>" + escape(d + p.notes) + "</desc>\n";
  svg += "<rect" + attr("x", "0") + attr("y", "0") + attr("width", px(l.W)) +
         attr("height", px(l.H)) + attr("fill", "white") + "/>\n";
  // the series are clipped to the plot area, widened by a marker so that a
  // point on an axis limit shows whole
  double m = kMarkerRadius + 1.0;
  for (const SeriesLook& look : chart.looks) {
    m = std::max(m, marker_radius(look) + 1.0);
  }
  svg += "<defs><clipPath" + attr("id", id + "plot-clip") + "><rect" +
         attr("x", px(l.left - m)) + attr("y", px(l.top - m)) +
         attr("width", px(l.plot_w + 2.0 * m)) +
         attr("height", px(l.plot_h + 2.0 * m)) + "/></clipPath></defs>\n";
  const double cx = l.left + 0.5 * l.plot_w;
  if (!chart.title.empty()) {
    svg += "<text" + attr("class", "title") + attr("x", px(cx)) +
           attr("y", px(0.5 * kMarginTop + 4.0)) + attr("text-anchor", "middle") +
           attr("font-size", "14") + ">" + escape(chart.title) + "</text>\n";
  }
  if (!chart.subtitle.empty()) {
    svg += "<text" + attr("class", "subtitle") + attr("x", px(cx)) +
           attr("y", px(0.5 * kMarginTop + 4.0 + kSubtitleRow + 1.0)) +
           attr("text-anchor", "middle") + attr("fill", chart.subtitle_color) +
           ">" + escape(chart.subtitle) + "</text>\n";
  }
  return svg;
}

// the bands, under everything else in the plot area
std::string bands_svg(const Chart& chart, const Layout& l, const Scale& sx,
                      const std::string& id) {
  if (chart.bands.empty()) return "";
  std::string svg = "<g" + attr("class", "bands") +
                    attr("clip-path", "url(#" + id + "plot-clip)") + ">\n";
  for (const ChartBand& b : chart.bands) {
    if (!std::isfinite(b.x0) || !std::isfinite(b.x1)) continue;
    if (sx.log && (b.x0 <= 0.0 || b.x1 <= 0.0)) continue;
    const double a = sx.to_px(std::min(b.x0, b.x1));
    const double z = sx.to_px(std::max(b.x0, b.x1));
    // clamped to the plot area (the clip path is a marker wider)
    const double from = std::clamp(a, l.left, l.left + l.plot_w);
    const double to = std::clamp(z, l.left, l.left + l.plot_w);
    svg += "<rect" + attr("x", px(from)) + attr("y", px(l.top)) +
           attr("width", px(to - from)) + attr("height", px(l.plot_h)) +
           attr("fill", b.color) + "/>\n";
  }
  return svg + "</g>\n";
}

// grid lines, ticks and their numbers along one axis
std::string x_ticks_svg(const Chart& chart, const Prepared& p, const Layout& l,
                        const Scale& sx) {
  std::string svg;
  for (const Tick& t : chart.x.log ? log_ticks(p.x0, p.x1) : linear_ticks(p.x0, p.x1)) {
    const double X = sx.to_px(t.value);
    svg += "<line" + attr("x1", px(X)) + attr("y1", px(l.top)) +
           attr("x2", px(X)) + attr("y2", px(l.bottom)) +
           attr("stroke", t.major ? "#dddddd" : "#f0f0f0") + "/>\n";
    svg += "<line" + attr("x1", px(X)) + attr("y1", px(l.bottom)) +
           attr("x2", px(X)) + attr("y2", px(l.bottom + (t.major ? 5.0 : 3.0))) +
           attr("stroke", "#444") + "/>\n";
    if (t.major) {
      svg += "<text" + attr("class", "tick-label") + attr("x", px(X)) +
             attr("y", px(l.bottom + 17.0)) + attr("text-anchor", "middle") +
             ">" + tick_text(t.value, chart.x.log) + "</text>\n";
    }
  }
  return svg;
}

std::string y_ticks_svg(const Chart& chart, const Prepared& p, const Layout& l,
                        const Scale& sy) {
  std::string svg;
  for (const Tick& t : chart.y.log ? log_ticks(p.y0, p.y1) : linear_ticks(p.y0, p.y1)) {
    const double Y = sy.to_px(t.value);
    svg += "<line" + attr("x1", px(l.left)) + attr("y1", px(Y)) +
           attr("x2", px(l.left + l.plot_w)) + attr("y2", px(Y)) +
           attr("stroke", t.major ? "#dddddd" : "#f0f0f0") + "/>\n";
    svg += "<line" + attr("x1", px(l.left - (t.major ? 5.0 : 3.0))) +
           attr("y1", px(Y)) + attr("x2", px(l.left)) + attr("y2", px(Y)) +
           attr("stroke", "#444") + "/>\n";
    if (t.major) {
      svg += "<text" + attr("class", "tick-label") + attr("x", px(l.left - 7.0)) +
             attr("y", px(Y + 4.0)) + attr("text-anchor", "end") + ">" +
             tick_text(t.value, chart.y.log) + "</text>\n";
    }
  }
  return svg;
}

// the plot area's frame (its x, y, width and height are the pixels of the
// axes' limits) and the axis labels
std::string frame_svg(const Chart& chart, const Layout& l, const std::string& id) {
  std::string svg = "<rect" + attr("class", "plot-area") + attr("x", px(l.left)) +
                    attr("y", px(l.top)) + attr("width", px(l.plot_w)) +
                    attr("height", px(l.plot_h)) + attr("fill", "none") +
                    attr("stroke", "#444") + "/>\n";
  svg += "<text" + attr("class", "axis-label") + attr("id", id + "x-label") +
         attr("x", px(l.left + 0.5 * l.plot_w)) + attr("y", px(l.bottom + 38.0)) +
         attr("text-anchor", "middle") + ">" + escape(chart.x.label) +
         "</text>\n";
  const double lx = 18.0, ly = l.top + 0.5 * l.plot_h;
  svg += "<text" + attr("class", "axis-label") + attr("id", id + "y-label") +
         attr("x", px(lx)) + attr("y", px(ly)) +
         attr("transform", "rotate(-90 " + px(lx) + " " + px(ly) + ")") +
         attr("text-anchor", "middle") + ">" + escape(chart.y.label) +
         "</text>\n";
  return svg;
}

// one series, clipped to the plot area
std::string series_svg(const ChartSeries& s, const SeriesLook& look,
                       const Kept& k, const std::string& color, const Scale& sx,
                       const Scale& sy, const std::string& id, std::size_t i) {
  std::string svg = "<g" + attr("class", "series") +
                    attr("id", id + "series-" + std::to_string(i)) +
                    attr("clip-path", "url(#" + id + "plot-clip)") + ">\n";
  svg += "<desc>" +
         escape(s.label + ": " + std::to_string(k.pts.size()) +
                " points drawn, " + std::to_string(k.non_finite) +
                " non-finite and " + std::to_string(k.non_positive) +
                " non-positive (log axis) dropped") +
         "</desc>\n";
  if (s.line && k.pts.size() >= 2) {
    std::string p;
    for (const auto& [x, y] : k.pts) {
      if (!p.empty()) p += ' ';
      p += px(sx.to_px(x)) + "," + px(sy.to_px(y));
    }
    svg += "<polyline" + attr("points", p) + attr("fill", "none") +
           stroke_attrs(s, look, color) + "/>\n";
  }
  if (s.markers) {
    for (const auto& [x, y] : k.pts) {
      svg += "<circle" + attr("cx", px(sx.to_px(x))) +
             attr("cy", px(sy.to_px(y))) + attr("r", px(marker_radius(look))) +
             marker_paint(look, color) + "/>\n";
    }
  }
  return svg + "</g>\n";
}

// the legend: a sample of each labelled series' line and marker, and its label
std::string legend_svg(const Chart& chart, const Prepared& p, const Layout& l) {
  if (l.legend_rows == 0) return "";
  const double lx = l.left + l.plot_w + kLegendGap;
  double ly = l.top + 8.0;
  std::string svg = "<g" + attr("class", "legend") + ">\n";
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const ChartSeries& s = chart.series[i];
    if (s.label.empty()) continue;
    if (s.line) {
      svg += "<line" + attr("x1", px(lx)) + attr("y1", px(ly)) +
             attr("x2", px(lx + kLegendSample)) + attr("y2", px(ly)) +
             stroke_attrs(s, look_of(chart, i), p.colors[i]) + "/>\n";
    }
    if (s.markers) {
      // a rounded square that looks like the markers: a <circle> here would
      // count as one of the series' markers to a reader of the file
      const double r = marker_radius(look_of(chart, i));
      svg += "<rect" + attr("x", px(lx + 0.5 * kLegendSample - r)) +
             attr("y", px(ly - r)) + attr("width", px(2.0 * r)) +
             attr("height", px(2.0 * r)) + attr("rx", px(r)) +
             marker_paint(look_of(chart, i), p.colors[i]) + "/>\n";
    }
    svg += "<text" + attr("x", px(lx + kLegendSample + 6.0)) +
           attr("y", px(ly + 4.0)) + ">" + escape(s.label) + "</text>\n";
    ly += kLegendRow;
  }
  return svg + "</g>\n";
}

// Everything inside the chart's <svg> element; element ids start with `id`.
std::string chart_body(const Chart& chart, const std::string& id) {
  const Prepared p = prepare(chart);
  const Layout l = layout(chart);
  const Scale sx{chart.x.log, p.x0, p.x1, l.left, l.left + l.plot_w};
  const Scale sy{chart.y.log, p.y0, p.y1, l.bottom, l.top};  // y up
  std::string svg = head_svg(chart, p, l, id);
  svg += bands_svg(chart, l, sx, id);
  svg += "<g" + attr("class", "axes") + ">\n" + x_ticks_svg(chart, p, l, sx) +
         y_ticks_svg(chart, p, l, sy) + "</g>\n";
  svg += frame_svg(chart, l, id);
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    svg += series_svg(chart.series[i], look_of(chart, i), p.kept[i],
                      p.colors[i], sx, sy, id, i);
  }
  return svg + legend_svg(chart, p, l);
}

// the <svg> element's size and font
std::string size_attrs(double W, double H) {
  return attr("width", px(W)) + attr("height", px(H)) +
         attr("viewBox", "0 0 " + px(W) + " " + px(H)) +
         " font-family=\"sans-serif\" font-size=\"11\"";
}

}  // namespace

std::string chart_svg(const Chart& chart) {
  check_lengths(chart, "chart_svg");
  const double W = std::max(chart.width_px, 1);
  const double H = std::max(chart.height_px, 1);
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\"" +
         attr("class", "chart") + size_attrs(W, H) + ">\n" +
         chart_body(chart, "") + "</svg>\n";
}

std::string chart_grid_svg(const ChartGrid& grid) {
  int cell_w = 1, cell_h = 1;
  for (std::size_t k = 0; k < grid.panels.size(); ++k) {
    check_lengths(grid.panels[k], "chart_grid_svg: panel " + std::to_string(k));
    cell_w = std::max(cell_w, grid.panels[k].width_px);
    cell_h = std::max(cell_h, grid.panels[k].height_px);
  }
  const std::size_t cols = static_cast<std::size_t>(std::max(grid.columns, 1));
  const std::size_t rows = (grid.panels.size() + cols - 1) / cols;
  // the title's row, a row per note, and a gap
  const double head = (grid.title.empty() ? 0.0 : 30.0) +
                      18.0 * static_cast<double>(grid.notes.size()) + 6.0;
  const double W = static_cast<double>(cols) * cell_w;
  const double H = head + static_cast<double>(rows) * cell_h + 10.0;
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\"" +
                    attr("class", "chart-grid") + size_attrs(W, H) + ">\n";
  if (!grid.title.empty()) svg += "<title>" + escape(grid.title) + "</title>\n";
  svg += "<rect" + attr("width", px(W)) + attr("height", px(H)) +
         attr("fill", "white") + "/>\n";
  double y = 0.0;
  if (!grid.title.empty()) {
    y += 24.0;
    svg += "<text" + attr("class", "title") + attr("x", "10") + attr("y", px(y)) +
           attr("font-size", "15") + ">" + escape(grid.title) + "</text>\n";
  }
  for (const std::string& note : grid.notes) {
    y += 18.0;
    svg += "<text" + attr("class", "note") + attr("x", "10") + attr("y", px(y)) +
           attr("fill", "#555") + ">" + escape(note) + "</text>\n";
  }
  for (std::size_t k = 0; k < grid.panels.size(); ++k) {
    const Chart& c = grid.panels[k];
    const std::string id = "panel-" + std::to_string(k);
    svg += "<svg" + attr("class", "chart") + attr("id", id) +
           attr("x", px(static_cast<double>(k % cols) * cell_w)) +
           attr("y", px(head + static_cast<double>(k / cols) * cell_h)) +
           size_attrs(std::max(c.width_px, 1), std::max(c.height_px, 1)) +
           ">\n" + chart_body(c, id + "-") + "</svg>\n";
  }
  return svg + "</svg>\n";
}

}  // namespace vmh::output
