#include "thesis/thesis_svg.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "output/svg_text.h"
#include "thesis/path_svg.h"

namespace vmh::thesis {
namespace {

using output::svg::attr;
using output::svg::escape;
using output::svg::format;
using output::svg::nice_step;
using output::svg::px;

constexpr double kLeft_px = 64.0;
constexpr double kTop_px = 52.0;
constexpr double kPlotH_px = 150.0;
constexpr double kGap_px = 46.0;
constexpr double kPlane_px = 340.0;
// theta_V red and theta_R green, as the overlay and the views draw them
const char* const kV = "#d62728";
const char* const kR = "#2ca02c";

std::string thesis_num(double v) {
  std::string s = format("%.3g", v);
  return s == "-0" ? "0" : s;
}

// a colour for the share u in [0, 1] of the run: dark blue through teal to
// yellow, readable in grey as dark to light
std::string time_colour(double u) {
  u = std::clamp(u, 0.0, 1.0);
  const double stops[3][3] = {{0.18, 0.16, 0.48}, {0.13, 0.57, 0.55}, {0.95, 0.85, 0.15}};
  const double x = u * 2.0;
  const int k = x >= 1.0 ? 1 : 0;
  const double f = x - k;
  char buf[16];
  int c[3];
  for (int i = 0; i < 3; ++i) {
    c[i] = static_cast<int>(std::lround(255.0 * (stops[k][i] + f * (stops[k + 1][i] - stops[k][i]))));
  }
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c[0], c[1], c[2]);
  return buf;
}

struct Column {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  double sum = 0.0;
  int n = 0;
};

// A time plot's frame: t0..t1 (s) across `width` px from kLeft_px, lo..hi
// (rad) up kPlotH_px from top + kPlotH_px, ticks ystep apart.
struct TimeFrame {
  double t0 = 0.0, t1 = 1.0;
  double lo = 0.0, hi = 1.0, ystep = 1.0;
  double top = 0.0, width = 1.0;
  double X(double t) const { return kLeft_px + (t - t0) / (t1 - t0) * width; }
  double Y(double v) const {
    return top + kPlotH_px - (v - lo) / (hi - lo) * kPlotH_px;
  }
};

// The frame of theta_V[k] and theta_R[k]: the run's span (1 ns at least)
// and their finite values' range (1 rad around a constant), out to whole
// ticks of about a quarter of it.
TimeFrame time_frame(const std::vector<ThesisSample>& s, std::size_t k,
                     double top, double width) {
  TimeFrame f;
  f.top = top;
  f.width = width;
  f.t0 = s.front().t_s;
  f.t1 = std::max(s.back().t_s, f.t0 + 1e-9);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ThesisSample& r : s) {
    for (const auto* v : {&r.theta_v, &r.theta_r}) {
      if (k < v->size() && std::isfinite((*v)[k])) {
        lo = std::min(lo, (*v)[k]);
        hi = std::max(hi, (*v)[k]);
      }
    }
  }
  if (!(hi > lo)) { lo -= 0.5; hi += 0.5; }
  f.ystep = nice_step(hi - lo, 4.0);
  f.lo = std::floor(lo / f.ystep) * f.ystep;
  f.hi = std::ceil(hi / f.ystep) * f.ystep;
  return f;
}

// The plot's frame and ticks: theta (rad) on the left, t (s) below, and
// the t axis's name under the last plot only. `name` is "" or "_<k+1>".
std::string time_axes(const TimeFrame& f, bool last, const std::string& name) {
  const double top = f.top, width = f.width, ystep = f.ystep;
  std::string g = "<rect" + attr("x", px(kLeft_px)) + attr("y", px(top)) +
                  attr("width", px(width)) + attr("height", px(kPlotH_px)) +
                  " fill=\"none\" stroke=\"#444\"/>\n";
  for (double v = f.lo; v <= f.hi + 1e-9 * ystep; v += ystep) {
    g += "<line" + attr("x1", px(kLeft_px - 4)) + attr("y1", px(f.Y(v))) +
         attr("x2", px(kLeft_px)) + attr("y2", px(f.Y(v))) + " stroke=\"#444\"/>\n";
    g += "<text" + attr("x", px(kLeft_px - 6)) + attr("y", px(f.Y(v) + 4)) +
         " text-anchor=\"end\">" + thesis_num(std::abs(v) < 1e-9 * ystep ? 0.0 : v) + "</text>\n";
  }
  const double tstep = nice_step(f.t1 - f.t0, 8.0);
  for (double t = std::ceil(f.t0 / tstep) * tstep; t <= f.t1 + 1e-9; t += tstep) {
    g += "<line" + attr("x1", px(f.X(t))) + attr("y1", px(top + kPlotH_px)) +
         attr("x2", px(f.X(t))) + attr("y2", px(top + kPlotH_px + 4)) + " stroke=\"#444\"/>\n";
    g += "<text" + attr("x", px(f.X(t))) + attr("y", px(top + kPlotH_px + 16)) +
         " text-anchor=\"middle\">" + thesis_num(t) + "</text>\n";
  }
  if (last) {
    g += "<text" + attr("x", px(kLeft_px + width / 2)) + attr("y", px(top + kPlotH_px + 32)) +
         " text-anchor=\"middle\">t (s)</text>\n";
  }
  g += "<text" + attr("x", px(16)) + attr("y", px(top + kPlotH_px / 2)) +
       attr("transform", "rotate(-90 16 " + px(top + kPlotH_px / 2) + ")") +
       " text-anchor=\"middle\">" + escape("theta" + name + " (rad)") + "</text>\n";
  return g;
}

// theta_V[k] (which 0) or theta_R[k] (which 1) as a min/max band per pixel
// column, shaded, and the columns' means as a line.
std::string theta_bands(const std::vector<ThesisSample>& s, std::size_t k,
                        int which, const TimeFrame& f, int columns,
                        const char* colour) {
  const double t0 = f.t0, t1 = f.t1, width = f.width;
  std::vector<Column> col(static_cast<std::size_t>(columns));
  for (const ThesisSample& r : s) {
    const auto& v = which == 0 ? r.theta_v : r.theta_r;
    if (k >= v.size() || !std::isfinite(v[k])) continue;
    const int c = std::min(columns - 1, static_cast<int>((r.t_s - t0) / (t1 - t0) * columns));
    Column& cc = col[static_cast<std::size_t>(std::max(c, 0))];
    cc.lo = std::min(cc.lo, v[k]);
    cc.hi = std::max(cc.hi, v[k]);
    cc.sum += v[k];
    ++cc.n;
  }
  std::string upper, lower, mean;
  for (int c = 0; c < columns; ++c) {
    const Column& cc = col[static_cast<std::size_t>(c)];
    if (cc.n == 0) continue;
    const double x = kLeft_px + (c + 0.5) / columns * width;
    upper += (upper.empty() ? "M" : " L") + px(x) + "," + px(f.Y(cc.hi));
    lower = " L" + px(x) + "," + px(f.Y(cc.lo)) + lower;
    mean += (mean.empty() ? "M" : " L") + px(x) + "," + px(f.Y(cc.sum / cc.n));
  }
  std::string g = "<path class=\"band\"" + attr("d", upper + lower + " Z") +
                  attr("fill", colour) + " fill-opacity=\"0.25\" stroke=\"none\"/>\n";
  g += "<path" + attr("d", mean) + attr("stroke", colour) +
       " fill=\"none\" stroke-width=\"1.2\"/>\n";
  return g;
}

// theta_V[k] (which 0) or theta_R[k] (which 1) as a line through every row.
std::string theta_line(const std::vector<ThesisSample>& s, std::size_t k,
                       int which, const TimeFrame& f, const char* colour) {
  std::string d;
  for (const ThesisSample& r : s) {
    const auto& v = which == 0 ? r.theta_v : r.theta_r;
    if (k >= v.size() || !std::isfinite(v[k])) continue;
    d += (d.empty() ? "M" : " L") + px(f.X(r.t_s)) + "," + px(f.Y(v[k]));
  }
  return "<path" + attr("d", d) + attr("stroke", colour) +
         " fill=\"none\" stroke-width=\"1.2\"/>\n";
}

// one time plot of theta_V[k] and theta_R[k]: min/max bands per pixel
// column and their means, or every row's line when there are fewer rows
// than columns
std::string time_plot(const std::vector<ThesisSample>& s, std::size_t k,
                      double top, double width, int columns, bool last) {
  const TimeFrame f = time_frame(s, k, top, width);
  const std::string name = s.front().theta_v.size() > 1 ? "_" + std::to_string(k + 1) : "";
  std::string g = "<g class=\"theta\">\n" + time_axes(f, last, name);
  const bool bands = static_cast<int>(s.size()) > columns;
  for (int which = 0; which < 2; ++which) {
    const char* colour = which == 0 ? kV : kR;
    g += bands ? theta_bands(s, k, which, f, columns, colour)
               : theta_line(s, k, which, f, colour);
  }
  return g + "</g>\n";
}

// the wrist centre in the mechanism's plane (device x-y for the thesis's
// circles; the x-y projection for a sphere), coloured by time
std::string plane_plot(const std::vector<ThesisSample>& s, const ForceFieldPath& path,
                       double left, double top) {
  double lo[2] = {path.pivot_mm[0] - path.length_mm, path.pivot_mm[1] - path.length_mm};
  double hi[2] = {path.pivot_mm[0] + path.length_mm, path.pivot_mm[1] + path.length_mm};
  for (const ThesisSample& r : s) {
    for (int a = 0; a < 2; ++a) {
      if (!std::isfinite(r.p_mm[a])) continue;
      lo[a] = std::min(lo[a], r.p_mm[a]);
      hi[a] = std::max(hi[a], r.p_mm[a]);
    }
  }
  const double span = 1.1 * std::max({hi[0] - lo[0], hi[1] - lo[1], 1.0});
  const double c0 = 0.5 * (lo[0] + hi[0]), c1 = 0.5 * (lo[1] + hi[1]);
  const double sc = kPlane_px / span;
  auto X = [&](double a) { return left + kPlane_px / 2 + (a - c0) * sc; };
  auto Y = [&](double b) { return top + kPlane_px / 2 - (b - c1) * sc; };
  std::string g = "<g class=\"plane\">\n";
  g += "<rect" + attr("x", px(left)) + attr("y", px(top)) + attr("width", px(kPlane_px)) +
       attr("height", px(kPlane_px)) + " fill=\"none\" stroke=\"#444\"/>\n";
  const double step = nice_step(span, 5.0);
  for (int axis = 0; axis < 2; ++axis) {
    const double c = axis == 0 ? c0 : c1;
    for (double t = std::ceil((c - span / 2) / step) * step; t <= c + span / 2; t += step) {
      const std::string label = thesis_num(std::abs(t) < 1e-9 * step ? 0.0 : t);
      if (axis == 0) {
        g += "<line" + attr("x1", px(X(t))) + attr("y1", px(top + kPlane_px)) +
             attr("x2", px(X(t))) + attr("y2", px(top + kPlane_px + 4)) + " stroke=\"#444\"/>\n";
        g += "<text" + attr("x", px(X(t))) + attr("y", px(top + kPlane_px + 16)) +
             " text-anchor=\"middle\">" + label + "</text>\n";
      } else {
        g += "<line" + attr("x1", px(left - 4)) + attr("y1", px(Y(t))) + attr("x2", px(left)) +
             attr("y2", px(Y(t))) + " stroke=\"#444\"/>\n";
        g += "<text" + attr("x", px(left - 6)) + attr("y", px(Y(t) + 4)) +
             " text-anchor=\"end\">" + label + "</text>\n";
      }
    }
  }
  g += "<text" + attr("x", px(left + kPlane_px / 2)) + attr("y", px(top + kPlane_px + 32)) +
       " text-anchor=\"middle\">x (mm, device frame)</text>\n";
  g += "<text" + attr("x", px(left - 40)) + attr("y", px(top + kPlane_px / 2)) +
       attr("transform", "rotate(-90 " + px(left - 40) + " " + px(top + kPlane_px / 2) + ")") +
       " text-anchor=\"middle\">y (mm)</text>\n";
  // the path as the mechanism draws it (thesis/path_svg.h), in x-y
  g += path_elements(vm_path_of(path).primitives,
                     square_view(Vec3::UnitX(), Vec3::UnitY(), X, Y, sc, c0, c1,
                                 span),
                     "", attr("stroke", "#6fa8dc") + attr("stroke-width", "2"));
  // the trajectory in 200 pieces, each in the colour of its time
  const double t0 = s.front().t_s, t1 = std::max(s.back().t_s, t0 + 1e-9);
  const std::size_t pieces = 200;
  for (std::size_t p = 0; p < pieces; ++p) {
    const std::size_t a = p * (s.size() - 1) / pieces, b = (p + 1) * (s.size() - 1) / pieces;
    if (b <= a) continue;
    std::string d;
    const std::size_t stride = std::max<std::size_t>(1, (b - a) / 40);
    for (std::size_t i = a; i <= b; i += stride) {
      if (!std::isfinite(s[i].p_mm[0]) || !std::isfinite(s[i].p_mm[1])) continue;
      d += (d.empty() ? "M" : " L") + px(X(s[i].p_mm[0])) + "," + px(Y(s[i].p_mm[1]));
    }
    if (std::isfinite(s[b].p_mm[0]) && std::isfinite(s[b].p_mm[1])) {
      d += (d.empty() ? "M" : " L") + px(X(s[b].p_mm[0])) + "," + px(Y(s[b].p_mm[1]));
    }
    if (d.empty()) continue;
    g += "<path class=\"trajectory\"" + attr("d", d) +
         attr("stroke", time_colour((s[a].t_s - t0) / (t1 - t0))) +
         " fill=\"none\" stroke-width=\"1.6\"/>\n";
  }
  // the colour bar: time
  const double bx = left + kPlane_px + 18, bh = kPlane_px;
  for (int i = 0; i < 50; ++i) {
    g += "<rect" + attr("x", px(bx)) + attr("y", px(top + bh - (i + 1) * bh / 50)) +
         attr("width", "12") + attr("height", px(bh / 50 + 0.5)) +
         attr("fill", time_colour((i + 0.5) / 50)) + "/>\n";
  }
  g += "<text" + attr("x", px(bx + 16)) + attr("y", px(top + bh)) + ">" + thesis_num(t0) + " s</text>\n";
  g += "<text" + attr("x", px(bx + 16)) + attr("y", px(top + 10)) + ">" + thesis_num(t1) + " s</text>\n";
  return g + "</g>\n";
}

}  // namespace

std::vector<ThesisSample> thesis_samples_from_csv(const std::string& csv_text) {
  std::istringstream in(csv_text);
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error("trace: empty file");
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    std::string c;
    while (std::getline(h, c, ',')) header.push_back(c);
  }
  auto column = [&](const std::string& name, bool required) -> long {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) {
      if (required) throw std::runtime_error("trace: no column '" + name + "'");
      return -1;
    }
    return static_cast<long>(it - header.begin());
  };
  const long t = column("t_s", true);
  const long p[3] = {column("p_x_mm", true), column("p_y_mm", true), column("p_z_mm", true)};
  std::vector<long> v, r;
  for (int k = 1; k <= 5; ++k) {
    const long a = column("theta_v_" + std::to_string(k), k == 1);
    const long b = column("theta_r_" + std::to_string(k), k == 1);
    if (a < 0 || b < 0) break;
    v.push_back(a);
    r.push_back(b);
  }
  long last = std::max({t, p[0], p[1], p[2]});
  for (long c : v) last = std::max(last, c);
  for (long c : r) last = std::max(last, c);
  std::vector<ThesisSample> out;
  std::vector<double> cells(static_cast<std::size_t>(last) + 1);
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const char* q = line.c_str();
    for (long c = 0; c <= last; ++c) {
      char* end = nullptr;
      cells[static_cast<std::size_t>(c)] = std::strtod(q, &end);
      if (end == q || (*end != ',' && *end != '\0')) {
        throw std::runtime_error("trace: line " + std::to_string(line_no) +
                                 ": column " + header[static_cast<std::size_t>(c)] +
                                 " is not a number");
      }
      q = *end == ',' ? end + 1 : end;
    }
    ThesisSample s;
    s.t_s = cells[static_cast<std::size_t>(t)];
    for (int a = 0; a < 3; ++a) s.p_mm[a] = cells[static_cast<std::size_t>(p[a])];
    for (long c : v) s.theta_v.push_back(cells[static_cast<std::size_t>(c)]);
    for (long c : r) s.theta_r.push_back(cells[static_cast<std::size_t>(c)]);
    out.push_back(std::move(s));
  }
  return out;
}

std::string thesis_svg(const std::vector<ThesisSample>& samples,
                       const ForceFieldPath& path, int columns) {
  const double plot_w = static_cast<double>(std::max(columns, 50));
  const std::size_t dof = samples.empty() ? 1 : samples.front().theta_v.size();
  const double width = kLeft_px + plot_w + 96.0 + kPlane_px + 90.0;
  const double plots_h = static_cast<double>(dof) * (kPlotH_px + kGap_px);
  const double height = kTop_px + std::max(plots_h, kPlane_px + 46.0) + 10.0;
  std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\"" + attr("width", px(width)) +
      attr("height", px(height)) + attr("viewBox", "0 0 " + px(width) + " " + px(height)) +
      " font-family=\"sans-serif\" font-size=\"11\">\n<rect x=\"0\" y=\"0\"" +
      attr("width", px(width)) + attr("height", px(height)) + " fill=\"white\"/>\n";
  if (samples.size() < 2) {
    return svg + "<text x=\"10\" y=\"30\">thesis figures: fewer than two rows</text>\n</svg>\n";
  }
  const bool bands = static_cast<int>(samples.size()) > columns;
  const bool planar = vm_path_of(path).planar;
  svg += "<text x=\"10\" y=\"18\" font-size=\"13\">" +
         escape("The VM's joint against time, theta_V (red) and theta_R (green), and "
                "the RM wrist centre in the mechanism's plane coloured by time") +
         "</text>\n";
  svg += "<text x=\"10\" y=\"34\" fill=\"#555\">" +
         escape(bands ? std::to_string(samples.size()) + " ticks: each pixel column's "
                        "minimum to maximum as a band, its mean as a line"
                      : std::to_string(samples.size()) + " ticks, every one drawn") +
         escape(planar ? "; right: the " + path.vm_kind + "'s plane (device x-y)"
                       : std::string("; right: the x-y projection")) +
         "</text>\n";
  for (std::size_t k = 0; k < dof; ++k) {
    svg += time_plot(samples, k, kTop_px + static_cast<double>(k) * (kPlotH_px + kGap_px),
                     plot_w, columns, k + 1 == dof);
  }
  svg += plane_plot(samples, path, kLeft_px + plot_w + 96.0, kTop_px);
  return svg + "</svg>\n";
}

}  // namespace vmh::thesis
