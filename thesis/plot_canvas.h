// The SVG canvas the case figures draw on (thesis/plot_svg.cc): a small
// writer (Svg), the data-to-pixel frame with its axes and ticks, arrows,
// decimation to kPlotMaxPoints, and the empty document. Internal to
// studies/.
#ifndef VMHAPTICS_THESIS_PLOT_CANVAS_H_
#define VMHAPTICS_THESIS_PLOT_CANVAS_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "output/svg_text.h"
#include "sim/cases/case.h"
#include "thesis/plot_svg.h"

namespace vmh::thesis::plot_detail {

using output::svg::attr;
using output::svg::escape;
using output::svg::format;
using output::svg::nice_step;
using output::svg::px;

using Pt = std::pair<double, double>;

// ---------------------------------------------------------------- text

// a number a reader reads: tick labels, titles
inline std::string plot_num(double v) {
  std::string s = format("%.4g", v);
  if (s == "-0") s = "0";
  return s;
}

// ---------------------------------------------------------------- writer

// Appends SVG elements to a string. `attrs` are extra attributes, each
// starting with a space (attr() makes them).
class Svg {
 public:
  Svg(double width, double height) {
    s_ = "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\"" +
         attr("width", px(width)) + attr("height", px(height)) +
         attr("viewBox", "0 0 " + px(width) + " " + px(height)) +
         " font-family=\"sans-serif\" font-size=\"11\">\n";
    rect(0.0, 0.0, width, height, attr("fill", "white"));
  }

  void line(double x1, double y1, double x2, double y2,
            const std::string& attrs) {
    s_ += "<line" + attr("x1", px(x1)) + attr("y1", px(y1)) +
          attr("x2", px(x2)) + attr("y2", px(y2)) + attrs + "/>\n";
  }
  // non-finite points are left out
  void polyline(const std::vector<Pt>& pts, const std::string& attrs) {
    std::string p;
    int n = 0;
    for (const Pt& q : pts) {
      if (!std::isfinite(q.first) || !std::isfinite(q.second)) continue;
      if (n++ > 0) p += ' ';
      p += px(q.first) + "," + px(q.second);
    }
    if (n < 2) return;
    s_ += "<polyline fill=\"none\" points=\"" + p + "\"" + attrs + "/>\n";
  }
  void polygon(const std::vector<Pt>& pts, const std::string& attrs) {
    std::string p;
    for (const Pt& q : pts) {
      if (!p.empty()) p += ' ';
      p += px(q.first) + "," + px(q.second);
    }
    s_ += "<polygon points=\"" + p + "\"" + attrs + "/>\n";
  }
  void circle(double cx, double cy, double r, const std::string& attrs) {
    s_ += "<circle" + attr("cx", px(cx)) + attr("cy", px(cy)) +
          attr("r", px(r)) + attrs + "/>\n";
  }
  void rect(double x, double y, double w, double h, const std::string& attrs) {
    s_ += "<rect" + attr("x", px(x)) + attr("y", px(y)) +
          attr("width", px(std::max(w, 0.0))) +
          attr("height", px(std::max(h, 0.0))) + attrs + "/>\n";
  }
  void text(double x, double y, const std::string& t,
            const std::string& attrs) {
    s_ += "<text" + attr("x", px(x)) + attr("y", px(y)) + attrs + ">" +
          escape(t) + "</text>\n";
  }
  // text turned to read upward, centred on (x, y)
  void vertical_text(double x, double y, const std::string& t,
                     const std::string& attrs) {
    text(x, y, t,
         attr("transform", "rotate(-90 " + px(x) + " " + px(y) + ")") +
             attr("text-anchor", "middle") + attrs);
  }
  void open(const std::string& tag, const std::string& attrs) {
    s_ += "<" + tag + attrs + ">\n";
  }
  void close(const std::string& tag) { s_ += "</" + tag + ">\n"; }
  // a clip path named `id` around a rectangle
  void clip_rect(const std::string& id, double x, double y, double w,
                 double h) {
    open("clipPath", attr("id", id));
    rect(x, y, w, h, "");
    close("clipPath");
  }

  // elements made elsewhere (thesis/path_svg.h)
  void raw(const std::string& elements) { s_ += elements; }
  std::string finish() const { return s_ + "</svg>\n"; }

 private:
  std::string s_;
};

// ---------------------------------------------------------------- axes

struct Bounds {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
};

inline long step_index_up(double v, double step) {
  return static_cast<long>(std::ceil(v / step - 1e-9));
}
inline long step_index_down(double v, double step) {
  return static_cast<long>(std::floor(v / step + 1e-9));
}

// the multiples of `step` in [lo, hi], with -0 and rounding noise removed
inline std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> t;
  for (long k = step_index_up(lo, step); k <= step_index_down(hi, step); ++k) {
    t.push_back(static_cast<double>(k) * step);
  }
  return t;
}

// A plot area: data ranges mapped to a pixel rectangle, y up.
struct Frame {
  double left = 0.0, top = 0.0, width = 1.0, height = 1.0;  // px
  double xlo = 0.0, xhi = 1.0, ylo = 0.0, yhi = 1.0;        // data
  double xstep = 1.0, ystep = 1.0;                           // ticks

  double X(double x) const { return left + (x - xlo) / (xhi - xlo) * width; }
  double Y(double y) const { return top + (yhi - y) / (yhi - ylo) * height; }
  Pt at(double x, double y) const { return {X(x), Y(y)}; }
};

// Grid, frame, ticks with numbers and the axis labels. The x numbers and
// label are left out when x_numbers is false (panels sharing a time axis).
inline void draw_axes(Svg& svg, const Frame& f, const std::string& xlabel,
               const std::string& ylabel, bool x_numbers) {
  const double bottom = f.top + f.height;
  for (double x : ticks(f.xlo, f.xhi, f.xstep)) {
    const double X = f.X(x);
    svg.line(X, f.top, X, bottom, attr("stroke", "#e4e4e4"));
    svg.line(X, bottom, X, bottom + 4.0, attr("stroke", "#444"));
    if (x_numbers) {
      svg.text(X, bottom + 15.0, plot_num(x), attr("text-anchor", "middle"));
    }
  }
  for (double y : ticks(f.ylo, f.yhi, f.ystep)) {
    const double Y = f.Y(y);
    svg.line(f.left, Y, f.left + f.width, Y,
             attr("stroke", y == 0.0 ? "#b0b0b0" : "#e4e4e4"));
    svg.line(f.left - 4.0, Y, f.left, Y, attr("stroke", "#444"));
    svg.text(f.left - 6.0, Y + 4.0, plot_num(y), attr("text-anchor", "end"));
  }
  svg.rect(f.left, f.top, f.width, f.height,
           attr("fill", "none") + attr("stroke", "#444"));
  if (x_numbers) {
    svg.text(f.left + 0.5 * f.width, bottom + 32.0, xlabel,
             attr("text-anchor", "middle"));
  }
  svg.vertical_text(f.left - 44.0, f.top + 0.5 * f.height, ylabel, "");
}

// every k-th index of n so that at most kPlotMaxPoints are kept, and n - 1
inline std::vector<std::size_t> decimated(std::size_t n) {
  std::vector<std::size_t> idx;
  if (n == 0) return idx;
  const std::size_t k = (n + kPlotMaxPoints - 1) / kPlotMaxPoints;
  for (std::size_t i = 0; i < n; i += k) idx.push_back(i);
  if (idx.back() != n - 1) idx.push_back(n - 1);
  return idx;
}

// an arrow from (x1, y1) to (x2, y2) in px: the shaft is a <line> carrying
// `attrs` (and an id), the head a polygon
inline void arrow(Svg& svg, double x1, double y1, double x2, double y2,
           const std::string& color, const std::string& attrs) {
  svg.line(x1, y1, x2, y2,
           attr("stroke", color) + attr("stroke-width", "2") + attrs);
  const double dx = x2 - x1, dy = y2 - y1;
  const double len = std::hypot(dx, dy);
  if (len < 4.0) return;
  const double ux = dx / len, uy = dy / len;
  const double head = std::min(9.0, 0.5 * len), half = 0.4 * head;
  const double bx = x2 - head * ux, by = y2 - head * uy;
  svg.polygon({{x2, y2}, {bx - half * uy, by + half * ux},
               {bx + half * uy, by - half * ux}},
              attr("fill", color));
}

inline std::string case_name(const sim::Case& the_case) {
  const std::string stem =
      std::filesystem::path(the_case.config().scene_path()).stem().string();
  return stem.empty() ? std::string("run") : stem;
}

inline std::string empty_document(const std::string& title) {
  Svg svg(480.0, 60.0);
  svg.text(10.0, 35.0, title + ": no rows to plot", attr("font-size", "14"));
  return svg.finish();
}


}  // namespace vmh::thesis::plot_detail

#endif  // VMHAPTICS_THESIS_PLOT_CANVAS_H_
