#include "thesis/force_field_svg.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "output/svg_text.h"
#include "thesis/path_svg.h"

namespace vmh::thesis {
namespace {

using output::svg::attr;
using output::svg::escape;
using output::svg::format;
using output::svg::px;

constexpr double kPanel_px = 360.0;   // each panel's square plot area
constexpr double kMargin_px = 48.0;
constexpr double kTitle_px = 46.0;
// the largest arrow spans this share of the panel's data range
constexpr double kLongestArrowShare = 0.18;
constexpr double kMinArrow_px = 2.0;

struct View {
  std::string tag;  // "xy", "xz", "zy"
  int across = 0;   // device axis drawn to the right
  int up = 1;       // device axis drawn upward
};

const char* axis_name(int i) { return i == 0 ? "x" : i == 1 ? "y" : "z"; }

std::string field_num(double v) {
  std::string s = format("%.3g", v);
  return s == "-0" ? "0" : s;
}

// A panel's equal-aspect square: span mm across centred on (c0, c1) of the
// view's axes, kPanel_px wide with its top left corner at (left, top).
struct PanelFrame {
  double left = 0.0, top = 0.0;
  double c0 = 0.0, c1 = 0.0;  // mm
  double span = 1.0;          // mm
  double scale = 1.0;         // px per mm
  double X(double a) const { return left + kPanel_px / 2 + (a - c0) * scale; }
  double Y(double b) const { return top + kPanel_px / 2 - (b - c1) * scale; }
};

// The square around the path (L to either side of the pivot) and the
// finite points of the trajectory, 15% wider than they are, 1 mm at least.
PanelFrame panel_frame(const std::vector<ForceSample>& s,
                       const ForceFieldPath& path, const View& v, double left,
                       double top) {
  double lo[2] = {path.pivot_mm[v.across] - path.length_mm,
                  path.pivot_mm[v.up] - path.length_mm};
  double hi[2] = {path.pivot_mm[v.across] + path.length_mm,
                  path.pivot_mm[v.up] + path.length_mm};
  for (const ForceSample& r : s) {
    const double a = r.p_mm[v.across], b = r.p_mm[v.up];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    lo[0] = std::min(lo[0], a), hi[0] = std::max(hi[0], a);
    lo[1] = std::min(lo[1], b), hi[1] = std::max(hi[1], b);
  }
  PanelFrame f;
  f.left = left;
  f.top = top;
  f.span = 1.15 * std::max({hi[0] - lo[0], hi[1] - lo[1], 1.0});
  f.c0 = 0.5 * (lo[0] + hi[0]);
  f.c1 = 0.5 * (lo[1] + hi[1]);
  f.scale = kPanel_px / f.span;
  return f;
}

// The panel's frame, its axes' names (the vertical one left of its tick
// labels, both outside the frame) and ticks in mm on both axes, at a step
// giving about five of them.
std::string panel_axes(const PanelFrame& f, const View& v) {
  const double left = f.left, top = f.top, span = f.span;
  std::string g = "<rect" + attr("x", px(left)) + attr("y", px(top)) +
                  attr("width", px(kPanel_px)) + attr("height", px(kPanel_px)) +
                  " fill=\"none\" stroke=\"#444\"/>\n";
  g += "<text" + attr("x", px(left + kPanel_px / 2)) +
       attr("y", px(top + kPanel_px + 32)) + " text-anchor=\"middle\">" +
       escape(std::string(axis_name(v.across)) + " (mm, device frame)") +
       "</text>\n";
  g += "<text" + attr("x", px(left - 36)) + attr("y", px(top + kPanel_px / 2)) +
       attr("transform", "rotate(-90 " + px(left - 36) + " " +
                             px(top + kPanel_px / 2) + ")") +
       " text-anchor=\"middle\">" +
       escape(std::string(axis_name(v.up)) + " (mm)") + "</text>\n";
  const double step = output::svg::nice_step(span, 5.0);
  for (int axis = 0; axis < 2; ++axis) {
    const double c = axis == 0 ? f.c0 : f.c1;
    for (double t = std::ceil((c - span / 2) / step) * step; t <= c + span / 2;
         t += step) {
      const std::string label = field_num(std::abs(t) < 1e-9 * step ? 0.0 : t);
      if (axis == 0) {
        g += "<line" + attr("x1", px(f.X(t))) + attr("y1", px(top + kPanel_px)) +
             attr("x2", px(f.X(t))) + attr("y2", px(top + kPanel_px + 4)) +
             " stroke=\"#444\"/>\n<text" + attr("x", px(f.X(t))) +
             attr("y", px(top + kPanel_px + 15)) +
             " text-anchor=\"middle\">" + label + "</text>\n";
      } else {
        g += "<line" + attr("x1", px(left - 4)) + attr("y1", px(f.Y(t))) +
             attr("x2", px(left)) + attr("y2", px(f.Y(t))) +
             " stroke=\"#444\"/>\n<text" + attr("x", px(left - 6)) +
             attr("y", px(f.Y(t) + 4)) + " text-anchor=\"end\">" + label +
             "</text>\n";
      }
    }
  }
  return g;
}

// The trajectory as a grey polyline, thinned to about 1500 points, its
// non-finite points left out ("" when none is left).
std::string panel_trajectory(const std::vector<ForceSample>& s,
                             const PanelFrame& f, const View& v) {
  std::string pts;
  const std::size_t k = std::max<std::size_t>(1, s.size() / 1500);
  for (std::size_t i = 0; i < s.size(); i += k) {
    const double a = s[i].p_mm[v.across], b = s[i].p_mm[v.up];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    pts += (pts.empty() ? "" : " ") + px(f.X(a)) + "," + px(f.Y(b));
  }
  if (pts.empty()) return "";
  return "<polyline fill=\"none\" stroke=\"#999\" stroke-width=\"0.8\"" +
         attr("points", pts) + "/>\n";
}

// The force at each picked sample as an arrow from the wrist centre,
// mm_per_N mm per N in the view's plane; shorter than kMinArrow_px or not
// finite: none.
std::string panel_arrows(const std::vector<ForceSample>& s,
                         const std::vector<std::size_t>& picked,
                         const PanelFrame& f, const View& v, double mm_per_N) {
  std::string g;
  for (std::size_t i : picked) {
    const ForceSample& r = s[i];
    const double x1 = f.X(r.p_mm[v.across]), y1 = f.Y(r.p_mm[v.up]);
    const double dx = r.F_N[v.across] * mm_per_N * f.scale;
    const double dy = -r.F_N[v.up] * mm_per_N * f.scale;
    const double len = std::hypot(dx, dy);
    if (!(len >= kMinArrow_px) || !std::isfinite(x1) || !std::isfinite(y1)) {
      continue;
    }
    const double x2 = x1 + dx, y2 = y1 + dy;
    g += "<line class=\"force\"" + attr("data-t-s", format("%.9g", r.t_s)) +
         attr("x1", px(x1)) + attr("y1", px(y1)) + attr("x2", px(x2)) +
         attr("y2", px(y2)) + " stroke=\"#c2185b\" stroke-width=\"1.4\"/>\n";
    const double ux = dx / len, uy = dy / len;
    const double head = std::min(7.0, 0.45 * len), half = 0.4 * head;
    const double bx = x2 - head * ux, by = y2 - head * uy;
    g += "<polygon fill=\"#c2185b\"" +
         attr("points", px(x2) + "," + px(y2) + " " + px(bx - half * uy) +
                            "," + px(by + half * ux) + " " +
                            px(bx + half * uy) + "," + px(by - half * ux)) +
         "/>\n";
  }
  return g;
}

// one panel: the path (the circle, the line, or the sphere's outline in
// this projection), the trajectory and the arrows
std::string panel(const std::vector<ForceSample>& s,
                  const std::vector<std::size_t>& picked,
                  const ForceFieldPath& path, const View& v, double left,
                  double top, double mm_per_N) {
  const PanelFrame f = panel_frame(s, path, v, left, top);
  std::string g = "<g class=\"panel\"" + attr("id", "ff-" + v.tag) +
                  attr("data-axes", std::string(axis_name(v.across)) + "," +
                                        axis_name(v.up)) + ">\n";
  g += panel_axes(f, v);
  // the path as the mechanism draws it (thesis/path_svg.h)
  g += path_elements(
      vm_path_of(path).primitives,
      square_view(Vec3::Unit(v.across), Vec3::Unit(v.up),
                  [&f](double a) { return f.X(a); },
                  [&f](double b) { return f.Y(b); }, f.scale, f.c0, f.c1,
                  f.span),
      "ff-path-" + v.tag,
      attr("stroke", "#1f77b4") + attr("stroke-width", "1.5"));
  g += panel_trajectory(s, f, v);
  g += panel_arrows(s, picked, f, v, mm_per_N);
  return g + "</g>\n";
}

}  // namespace

VmPath vm_path_of(const ForceFieldPath& path) {
  if (!(path.length_mm > 0.0)) return {};
  return vm_path_mm(path.vm_kind,
                    Vec3(path.pivot_mm[0], path.pivot_mm[1], path.pivot_mm[2]),
                    path.length_mm);
}

std::string force_field_svg(const std::vector<ForceSample>& samples,
                            const ForceFieldPath& path, std::size_t arrows) {
  // a planar path (the circle, the line): one view, its plane
  const bool plane = vm_path_of(path).planar;
  std::vector<View> views;
  if (plane) {
    views = {{"xy", 0, 1}};
  } else {
    views = {{"xy", 0, 1}, {"xz", 0, 2}, {"zy", 2, 1}};
  }
  // wide enough for the caption over one panel
  const double width = std::max(
      760.0, kMargin_px + static_cast<double>(views.size()) *
                              (kPanel_px + kMargin_px));
  const double height = kTitle_px + kPanel_px + 46.0;
  std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\"" +
      attr("width", px(width)) + attr("height", px(height)) +
      attr("viewBox", "0 0 " + px(width) + " " + px(height)) +
      " font-family=\"sans-serif\" font-size=\"11\">\n" +
      "<rect x=\"0\" y=\"0\"" + attr("width", px(width)) +
      attr("height", px(height)) + " fill=\"white\"/>\n";
  if (samples.empty()) {
    return svg + "<text x=\"10\" y=\"30\">force field: no rows to plot</text>\n</svg>\n";
  }

  // samples evenly along the trajectory's length, not in time: where the
  // hand holds still, samples evenly in time pile their arrows on one spot
  // (issue 31); and the arrows' scale from the largest force
  std::vector<double> walked(samples.size(), 0.0);  // mm from the first row
  for (std::size_t i = 1; i < samples.size(); ++i) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = samples[i].p_mm[k] - samples[i - 1].p_mm[k];
      d2 += d * d;
    }
    const double d = std::sqrt(d2);
    walked[i] = walked[i - 1] + (std::isfinite(d) ? d : 0.0);
  }
  std::vector<std::size_t> picked;
  const std::size_t n = std::max<std::size_t>(1, arrows);
  const double total = walked.back();
  for (std::size_t j = 0, i = 0; j < n; ++j) {
    if (total <= 0.0) {
      i = (j * samples.size()) / n;  // no motion at all: evenly in time
    } else {
      const double at = total * static_cast<double>(j) / static_cast<double>(n);
      while (i + 1 < samples.size() && walked[i] < at) ++i;
    }
    if (picked.empty() || picked.back() != i) picked.push_back(i);
  }
  double max_F = 0.0;
  for (std::size_t i : picked) {
    const auto& F = samples[i].F_N;
    const double f = std::sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2]);
    if (std::isfinite(f)) max_F = std::max(max_F, f);
  }
  const double reach_mm = std::max(path.length_mm, 10.0) * 2.0;
  const double mm_per_N = max_F > 0.0 ? kLongestArrowShare * reach_mm / max_F : 0.0;

  svg += "<text x=\"" + px(kMargin_px) + "\" y=\"18\" font-size=\"13\">" +
         escape("Commanded force along the path (" + path.vm_kind + ", L = " +
                field_num(path.length_mm) + " mm): " + std::to_string(picked.size()) +
                " samples evenly along the trajectory's length") + "</text>\n";
  svg += "<text x=\"" + px(kMargin_px) + "\" y=\"34\">" +
         escape("device frame, mm; arrow 1 N = " + field_num(mm_per_N) +
                " mm; blue: the VM's path" +
                (plane ? std::string(" (its plane)")
                       : " (the " + path.vm_kind + "'s outline)") +
                "; grey: RM wrist centre; largest |F| " + field_num(max_F) + " N") +
         "</text>\n";
  for (std::size_t k = 0; k < views.size(); ++k) {
    svg += panel(samples, picked, path, views[k],
                 kMargin_px + static_cast<double>(k) * (kPanel_px + kMargin_px), kTitle_px,
                 mm_per_N);
  }
  return svg + "</svg>\n";
}

std::vector<ForceSample> force_samples_from_csv(const std::string& csv_text) {
  std::istringstream in(csv_text);
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error("trace: empty file");
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    std::string c;
    while (std::getline(h, c, ',')) header.push_back(c);
  }
  const char* const wanted[] = {"t_s",    "p_x_mm", "p_y_mm", "p_z_mm",
                                "F_x_N",  "F_y_N",  "F_z_N"};
  std::size_t col[7];
  std::size_t last = 0;
  for (int k = 0; k < 7; ++k) {
    const auto it = std::find(header.begin(), header.end(), wanted[k]);
    if (it == header.end()) {
      throw std::runtime_error(std::string("trace: no column '") + wanted[k] +
                               "'");
    }
    col[k] = static_cast<std::size_t>(it - header.begin());
    last = std::max(last, col[k]);
  }
  std::vector<ForceSample> out;
  std::vector<double> v(last + 1);
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    // the columns up to the last one wanted are numbers; the rest is skipped
    const char* p = line.c_str();
    for (std::size_t c = 0; c <= last; ++c) {
      char* end = nullptr;
      v[c] = std::strtod(p, &end);
      if (end == p || (*end != ',' && c < last)) {
        throw std::runtime_error("trace: line " + std::to_string(line_no) +
                                 ": column " + std::to_string(c + 1) +
                                 " is missing or not a number");
      }
      p = *end == ',' ? end + 1 : end;
    }
    ForceSample s;
    s.t_s = v[col[0]];
    for (int a = 0; a < 3; ++a) {
      s.p_mm[a] = v[col[1 + a]];
      s.F_N[a] = v[col[4 + a]];
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace vmh::thesis
