#include "thesis/plot_svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "output/svg_text.h"
#include "thesis/plot_canvas.h"
#include "thesis/path_svg.h"

namespace vmh::thesis {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

using namespace plot_detail;  // NOLINT(build/namespaces)

// ---------------------------------------------------------------- views

// a view: the horizontal and vertical axes as device-frame directions
struct Projection {
  std::string tag;    // "" or "xy", "xz", "zy"
  std::string title;  // shown under the panel's title
  Vec3 a, b;
  std::string xlabel, ylabel;
  // a device-frame point's horizontal and vertical coordinates (mm)
  double u(const Vec3& p) const { return a.dot(p); }
  double v(const Vec3& p) const { return b.dot(p); }
};

struct Snapshot {
  const char* segment;
  const char* tag;
  const char* what;
  const TickRecord* row = nullptr;
  std::string note;  // why there is no row
};

// the row nearest the middle of the settled half of `segment`, if the run
// has one within a servo period of it
void find_snapshot(const std::vector<TickRecord>& rows, const sim::Case& the_case,
                   Snapshot* s) {
  const ScriptSegment* seg = nullptr;
  for (const ScriptSegment& g : the_case.script().segments()) {
    if (g.name == s->segment) seg = &g;
  }
  if (seg == nullptr) {
    s->note = std::string("the script has no segment ") + s->segment;
    return;
  }
  const double mid = 0.5 * (seg->settled_from_s() + seg->t1_s);
  const TickRecord* best = nullptr;
  for (const TickRecord& r : rows) {
    if (best == nullptr || std::abs(r.t_s - mid) < std::abs(best->t_s - mid)) {
      best = &r;
    }
  }
  const double tol = 1.5 * the_case.controller_params().servo_period_s;
  if (best == nullptr || std::abs(best->t_s - mid) > tol) {
    s->note = "t = " + plot_num(mid) + " s (" + s->segment + ") is not in the run";
    return;
  }
  s->row = best;
}

struct ViewLayout {
  static constexpr double kPlot = 340.0;      // square plot area, px
  static constexpr double kLeft = 62.0;       // room for y numbers, label
  static constexpr double kTop = 44.0;        // two title lines
  static constexpr double kCellW = kLeft + kPlot + 22.0;
  static constexpr double kCellH = kTop + kPlot + 46.0;
  static constexpr double kHeader = 30.0;
  static constexpr double kLegendW = 300.0;
};

// the VM's path as its drawing hook gives it, device frame, mm
VmPath path_of(const VmParams& vm) {
  return vm_path_mm(vm_kind_name(vm.kind), vm.pivot_mm, vm.length_mm,
                    vm.R_pivot);
}

// What a view must show, in its own coordinates (mm): the pivot, the path
// (a circle or sphere whole, a line L to either side of its centre, a
// plane's handle path where it is edge-on), the RM's trail and, at the
// snapshot, p, X(theta_V), X(theta_R), the stylus tip and the force's tip.
// Both empty when nothing is finite.
void view_extent(const Projection& proj, const std::vector<PathPrimitive>& path,
                 const std::vector<TickRecord>& rows,
                 const std::vector<std::size_t>& idx, const TickRecord* r,
                 const VmParams& vm, Bounds* bu, Bounds* bv) {
  const double L = vm.length_mm;
  auto add = [&](const Vec3& p) {
    bu->add(proj.u(p));
    bv->add(proj.v(p));
  };
  add(vm.pivot_mm);
  for (const PathPrimitive& prim : path) {
    switch (prim.type) {
      case PathPrimitive::Type::kCircle:
      case PathPrimitive::Type::kSphere:
        bu->add(proj.u(prim.centre) - prim.radius);
        bu->add(proj.u(prim.centre) + prim.radius);
        bv->add(proj.v(prim.centre) - prim.radius);
        bv->add(proj.v(prim.centre) + prim.radius);
        break;
      case PathPrimitive::Type::kLine:
        add(prim.centre + L * prim.u);
        add(prim.centre - L * prim.u);
        break;
      case PathPrimitive::Type::kPlane: {
        const Vec3 n = prim.u.cross(prim.v);
        add(prim.centre + prim.radius * n);
        add(prim.centre - prim.radius * n);
        break;
      }
    }
  }
  for (std::size_t i : idx) add(rows[i].out.p_rm_mm);
  if (r != nullptr) {
    const ControlOutput& o = r->out;
    add(o.p_rm_mm);
    add(o.x_v_mm);
    add(o.x_r_mm);
    add(o.p_rm_mm + kPlotStylusMm * o.axis_rm);
    add(o.p_rm_mm + kPlotForceMmPerN * o.force_device_N);
  }
}

// The panel's plot area at (ox, oy): a square of whole ticks around the
// extent (L to either side of 0 when it is empty), with an 8 mm margin
// and at least 10 mm across.
Frame view_frame(double ox, double oy, Bounds bu, Bounds bv, double L) {
  if (bu.empty() || bv.empty()) {
    bu = Bounds{-L, L};
    bv = Bounds{-L, L};
  }
  const double pad = 8.0;
  const double span = std::max({bu.hi - bu.lo, bv.hi - bv.lo, 10.0}) + 2 * pad;
  const double step = nice_step(span, 6.0);
  const double cu = 0.5 * (bu.lo + bu.hi), cv = 0.5 * (bv.lo + bv.hi);
  long u0 = step_index_down(cu - 0.5 * span, step);
  long u1 = step_index_up(cu + 0.5 * span, step);
  long v0 = step_index_down(cv - 0.5 * span, step);
  long v1 = step_index_up(cv + 0.5 * span, step);
  const long cells = std::max(u1 - u0, v1 - v0);
  u0 -= (cells - (u1 - u0)) / 2;
  u1 = u0 + cells;
  v0 -= (cells - (v1 - v0)) / 2;
  v1 = v0 + cells;

  Frame f;
  f.left = ox + ViewLayout::kLeft;
  f.top = oy + ViewLayout::kTop;
  f.width = f.height = ViewLayout::kPlot;
  f.xlo = static_cast<double>(u0) * step;
  f.xhi = static_cast<double>(u1) * step;
  f.ylo = static_cast<double>(v0) * step;
  f.yhi = static_cast<double>(v1) * step;
  f.xstep = f.ystep = step;
  return f;
}

// The panel's two title lines (the case, the snapshot with its time and
// distance to the path, or why there is none; the view) and its axes.
void view_titles(Svg& svg, const Frame& f, double oy, const std::string& name,
                 const Snapshot& snap, const Projection& proj) {
  const TickRecord* r = snap.row;
  std::string title = name + ": " + snap.what;
  if (r != nullptr) {
    title += " (t = " + format("%.3f", r->t_s) + " s, d = " +
             format("%.3g", r->d_path_mm) + " mm)";
  }
  svg.text(f.left, oy + 16.0, title,
           attr("font-size", "12") + attr("font-weight", "bold"));
  svg.text(f.left, oy + 31.0,
           (r != nullptr ? std::string("stylus misaligned; ") : snap.note + "; ") +
               proj.title,
           attr("fill", "#444"));
  draw_axes(svg, f, proj.xlabel, proj.ylabel, true);
}

// The VM's path as its drawing hook gives it, the RM's trail over the run
// (decimated rows `idx`) and the pivot's cross.
void view_path_and_trail(Svg& svg, const Frame& f, const Projection& proj,
                         const std::vector<PathPrimitive>& path,
                         const std::vector<TickRecord>& rows,
                         const std::vector<std::size_t>& idx,
                         const VmParams& vm, const std::string& tag) {
  const double pu = proj.u(vm.pivot_mm), pv = proj.v(vm.pivot_mm);
  PathView view;
  view.a = proj.a;
  view.b = proj.b;
  view.X = [&f](double x) { return f.X(x); };
  view.Y = [&f](double y) { return f.Y(y); };
  view.px_per_mm = f.width / (f.xhi - f.xlo);
  view.lo[0] = f.xlo;
  view.lo[1] = f.ylo;
  view.hi[0] = f.xhi;
  view.hi[1] = f.yhi;
  svg.raw(path_elements(path, view, "path-" + tag,
                        attr("stroke", "#555") + attr("stroke-width", "1.2")));
  std::vector<Pt> trail;
  trail.reserve(idx.size());
  for (std::size_t i : idx) {
    trail.push_back(
        f.at(proj.u(rows[i].out.p_rm_mm), proj.v(rows[i].out.p_rm_mm)));
  }
  svg.polyline(trail, attr("stroke", "#a8a8a8") + attr("stroke-width", "0.8"));
  // the pivot
  svg.line(f.X(pu) - 4, f.Y(pv), f.X(pu) + 4, f.Y(pv), attr("stroke", "#000"));
  svg.line(f.X(pu), f.Y(pv) - 4, f.X(pu), f.Y(pv) + 4, attr("stroke", "#000"));
}

// The snapshot's tick: pivot -> X(theta_V) in red and pivot -> X(theta_R)
// in green, the stylus axis at p, the force from p (kPlotForceMmPerN mm per
// N) with its two components in this view dashed, and p.
void view_snapshot(Svg& svg, const Frame& f, const Projection& proj,
                   const ControlOutput& o, const VmParams& vm,
                   const std::string& tag) {
  auto u = [&](const Vec3& p) { return proj.u(p); };
  auto v = [&](const Vec3& p) { return proj.v(p); };
  const double pu = u(vm.pivot_mm), pv = v(vm.pivot_mm);
  const Vec3& p = o.p_rm_mm;
  svg.line(f.X(pu), f.Y(pv), f.X(u(o.x_v_mm)), f.Y(v(o.x_v_mm)),
           attr("id", "xv-" + tag) + attr("stroke", "#d00000") +
               attr("stroke-width", "2"));
  svg.circle(f.X(u(o.x_v_mm)), f.Y(v(o.x_v_mm)), 2.5, attr("fill", "#d00000"));
  svg.line(f.X(pu), f.Y(pv), f.X(u(o.x_r_mm)), f.Y(v(o.x_r_mm)),
           attr("id", "xr-" + tag) + attr("stroke", "#00a000") +
               attr("stroke-width", "2"));
  svg.circle(f.X(u(o.x_r_mm)), f.Y(v(o.x_r_mm)), 2.5, attr("fill", "#00a000"));
  const Vec3 tip = p + kPlotStylusMm * o.axis_rm;
  svg.line(f.X(u(p)), f.Y(v(p)), f.X(u(tip)), f.Y(v(tip)),
           attr("id", "stylus-" + tag) + attr("stroke", "#000") +
               attr("stroke-width", "3") + attr("stroke-linecap", "round"));
  // the force and its components in this view
  const Vec3 F = kPlotForceMmPerN * o.force_device_N;
  const std::string thin = attr("stroke", "#c000c0") +
                           attr("stroke-width", "1") +
                           attr("stroke-dasharray", "3 2");
  svg.line(f.X(u(p)), f.Y(v(p)), f.X(u(p) + u(F)), f.Y(v(p)), thin);
  svg.line(f.X(u(p)), f.Y(v(p)), f.X(u(p)), f.Y(v(p) + v(F)), thin);
  arrow(svg, f.X(u(p)), f.Y(v(p)), f.X(u(p) + u(F)), f.Y(v(p) + v(F)),
        "#c000c0", attr("id", "force-" + tag));
  svg.circle(f.X(u(p)), f.Y(v(p)), 3.0,
             attr("id", "p-" + tag) + attr("fill", "#000"));
}

// One view of one snapshot at (ox, oy): its extent, frame and titles, then
// the path, the trail and the snapshot's vectors clipped to the frame.
void view_panel(Svg& svg, double ox, double oy, const std::string& name,
                const Snapshot& snap, const Projection& proj,
                const std::vector<TickRecord>& rows, const VmParams& vm) {
  const std::string tag =
      std::string(snap.tag) + (proj.tag.empty() ? "" : "-" + proj.tag);
  // the path as the mechanism draws it (its drawing hook), mm
  const std::vector<PathPrimitive> path = path_of(vm).primitives;
  const std::vector<std::size_t> idx = decimated(rows.size());
  Bounds bu, bv;
  view_extent(proj, path, rows, idx, snap.row, vm, &bu, &bv);
  const Frame f = view_frame(ox, oy, bu, bv, vm.length_mm);

  svg.open("g", attr("class", "panel") + attr("id", "panel-" + tag));
  view_titles(svg, f, oy, name, snap, proj);
  svg.clip_rect("clip-" + tag, f.left, f.top, f.width, f.height);
  svg.open("g", attr("clip-path", "url(#clip-" + tag + ")"));
  view_path_and_trail(svg, f, proj, path, rows, idx, vm, tag);
  if (snap.row != nullptr) view_snapshot(svg, f, proj, snap.row->out, vm, tag);
  svg.close("g");
  svg.close("g");
}

void view_legend(Svg& svg, double x, double y, const VmParams& vm) {
  const VmPath vm_path = path_of(vm);
  const std::string kind = vm_path.label;
  bool plane = false;
  for (const PathPrimitive& prim : vm_path.primitives) {
    plane = plane || prim.type == PathPrimitive::Type::kPlane;
  }
  svg.open("g", attr("id", "legend"));
  svg.text(x, y, "Legend", attr("font-weight", "bold"));
  double yy = y + 20.0;
  auto item = [&](const std::string& label,
                  const std::function<void(double, double)>& sample) {
    sample(x, yy);
    svg.text(x + 34.0, yy + 4.0, label, "");
    yy += 20.0;
  };
  auto stroke = [&](const char* color, const char* width, const char* dash) {
    return [&svg, color, width, dash](double x0, double y0) {
      svg.line(x0, y0, x0 + 26.0, y0,
               attr("stroke", color) + attr("stroke-width", width) +
                   (dash[0] != '\0' ? attr("stroke-dasharray", dash) : ""));
    };
  };
  item("VM path: " + kind + ", L = " + plot_num(vm.length_mm) + " mm",
       stroke("#555", "1.2", plane ? "6 3" : ""));
  item("RM wrist centre p over the run", stroke("#a8a8a8", "0.8", ""));
  item("p at the snapshot", [&svg](double x0, double y0) {
    svg.circle(x0 + 13.0, y0, 3.0, attr("fill", "#000"));
  });
  item("pivot -> X(theta_V), the placed VM", stroke("#d00000", "2", ""));
  item("pivot -> X(theta_R), VM along the stylus", stroke("#00a000", "2", ""));
  item("stylus axis a at p, " + plot_num(kPlotStylusMm) + " mm",
       stroke("#000", "3", ""));
  item("force F from p, " + plot_num(kPlotForceMmPerN) + " mm per N",
       [&svg](double x0, double y0) {
         arrow(svg, x0, y0, x0 + 26.0, y0, "#c000c0", "");
       });
  item("components of F in the view", stroke("#c000c0", "1", "3 2"));
  item("pivot at (" + plot_num(vm.pivot_mm.x()) + ", " + plot_num(vm.pivot_mm.y()) +
           ", " + plot_num(vm.pivot_mm.z()) + ") mm",
       [&svg](double x0, double y0) {
         svg.line(x0 + 9.0, y0, x0 + 17.0, y0, attr("stroke", "#000"));
         svg.line(x0 + 13.0, y0 - 4.0, x0 + 13.0, y0 + 4.0,
                  attr("stroke", "#000"));
       });
  svg.text(x, yy + 10.0, "Device frame, mm; equal aspect.", attr("fill", "#444"));
  svg.text(x, yy + 26.0, "Snapshots: middle of the settled half of",
           attr("fill", "#444"));
  svg.text(x, yy + 40.0, "off_out_misaligned and on_misaligned_a.",
           attr("fill", "#444"));
  svg.close("g");
}

// ---------------------------------------------------------------- history

struct Series {
  std::string name;
  std::string color;
  std::string dash;  // "" solid
  std::function<double(const TickRecord&)> value;
};

struct HistoryPanel {
  std::string ylabel;
  std::string heading;
  std::vector<Series> series;
};

struct HistoryLayout {
  static constexpr double kLeft = 76.0;  // room for y numbers, label
  static constexpr double kPlotW = 800.0;
  static constexpr double kPlotH = 180.0;
  static constexpr double kGap = 22.0;   // between panels
  static constexpr double kTop = 58.0;   // title and segment names
  static constexpr double kLegendX = kLeft + kPlotW + 22.0;
  static constexpr double kWidth = kLegendX + 230.0;
  static constexpr double kHeight = kTop + 3.0 * kPlotH + 2.0 * kGap + 52.0;
};

// The three panels: (a) p - X(theta_V) per axis with the distance to the
// path, (b) p - X(theta_R) per axis, (c) the commanded force per axis and
// its magnitude.
std::vector<HistoryPanel> history_panels() {
  const char* const kColor[3] = {"#d62728", "#2ca02c", "#1f77b4"};
  const char* const kAxis[3] = {"x", "y", "z"};
  std::vector<HistoryPanel> panels(3);
  panels[0].ylabel = "(a) p - X(theta_V) (mm)";
  panels[0].heading = "(a) p - X(theta_V) (mm)";
  panels[1].ylabel = "(b) p - X(theta_R) (mm)";
  panels[1].heading = "(b) p - X(theta_R) (mm)";
  panels[2].ylabel = "(c) force F (N)";
  panels[2].heading = "(c) commanded force (N)";
  for (int i = 0; i < 3; ++i) {
    const std::string c = kAxis[i];
    panels[0].series.push_back({c, kColor[i], "", [i](const TickRecord& r) {
                                  return r.out.p_rm_mm[i] - r.out.x_v_mm[i];
                                }});
    panels[1].series.push_back({c, kColor[i], "", [i](const TickRecord& r) {
                                  return r.out.p_rm_mm[i] - r.out.x_r_mm[i];
                                }});
    panels[2].series.push_back({"F_" + c, kColor[i], "", [i](const TickRecord& r) {
                                  return r.out.force_device_N[i];
                                }});
  }
  panels[0].series.push_back({"d_path (distance to the path)", "#000", "5 3",
                              [](const TickRecord& r) { return r.d_path_mm; }});
  panels[2].series.push_back({"|F|", "#000", "5 3", [](const TickRecord& r) {
                                return r.out.force_device_N.norm();
                              }});
  return panels;
}

// The time axis the panels share: the run's first to last tick (1 ms at
// least), with ticks about a tenth of it apart, ending on a tick when the
// run nearly does (the last tick is at T - period). Only xlo, xhi and xstep
// are set.
Frame history_time_axis(const std::vector<TickRecord>& rows) {
  double t0 = rows.front().t_s, t1 = rows.back().t_s;
  if (!(t1 > t0)) t1 = t0 + 1e-3;
  const double tstep = nice_step(t1 - t0, 10.0);
  const double t_end = static_cast<double>(step_index_up(t1, tstep)) * tstep;
  if (t_end - t1 < 0.02 * (t1 - t0)) t1 = t_end;
  Frame f;
  f.xlo = t0;
  f.xhi = t1;
  f.xstep = tstep;
  return f;
}

// Panel k's plot area on the shared time axis: y over its series' values
// at the decimated rows `idx` and 0, with a 5% margin, on whole ticks.
Frame history_frame(const Frame& time, std::size_t k, const HistoryPanel& hp,
                    const std::vector<TickRecord>& rows,
                    const std::vector<std::size_t>& idx) {
  Frame f = time;
  f.left = HistoryLayout::kLeft;
  const double pitch = HistoryLayout::kPlotH + HistoryLayout::kGap;
  f.top = HistoryLayout::kTop + static_cast<double>(k) * pitch;
  f.width = HistoryLayout::kPlotW;
  f.height = HistoryLayout::kPlotH;
  Bounds b;
  b.add(0.0);
  for (const Series& s : hp.series) {
    for (std::size_t i : idx) b.add(s.value(rows[i]));
  }
  if (b.hi - b.lo < 1e-9) b.hi = b.lo + 1.0;
  const double pad = 0.05 * (b.hi - b.lo);
  f.ystep = nice_step(b.hi - b.lo + 2 * pad, 5.0);
  f.ylo = static_cast<double>(step_index_down(b.lo - pad, f.ystep)) * f.ystep;
  f.yhi = static_cast<double>(step_index_up(b.hi + pad, f.ystep)) * f.ystep;
  return f;
}

// The script's segments behind panel k: alternate shading, dashed
// boundaries, and on the first panel their names on top.
void history_segments(Svg& svg, const Frame& f, std::size_t k,
                      const std::vector<ScriptSegment>& segs) {
  const double t0 = f.xlo, t1 = f.xhi;
  for (std::size_t s = 0; s < segs.size(); ++s) {
    const double a = std::max(segs[s].t0_s, t0), e = std::min(segs[s].t1_s, t1);
    if (!(e > a)) continue;
    if (s % 2 == 1) {
      svg.rect(f.X(a), f.top, f.X(e) - f.X(a), f.height, attr("fill", "#f3f3f3"));
    }
    if (segs[s].t0_s > t0 && segs[s].t0_s < t1) {
      svg.line(f.X(segs[s].t0_s), f.top, f.X(segs[s].t0_s), f.top + f.height,
               attr("stroke", "#888") + attr("stroke-width", "0.7") +
                   attr("stroke-dasharray", "3 3"));
    }
    if (k == 0) {
      svg.text(0.5 * (f.X(a) + f.X(e)), f.top - (s % 2 == 0 ? 16.0 : 5.0),
               segs[s].name,
               attr("class", "segment") + attr("text-anchor", "middle") +
                   attr("font-size", "9") + attr("fill", "#555"));
    }
  }
}

// The panel's series as lines at the decimated rows, clipped to its frame.
void history_lines(Svg& svg, const Frame& f, const HistoryPanel& hp,
                   const std::vector<TickRecord>& rows,
                   const std::vector<std::size_t>& idx,
                   const std::string& tag) {
  svg.clip_rect("clip-history-" + tag, f.left, f.top, f.width, f.height);
  svg.open("g", attr("clip-path", "url(#clip-history-" + tag + ")"));
  for (const Series& s : hp.series) {
    std::vector<Pt> pts;
    pts.reserve(idx.size());
    for (std::size_t i : idx) pts.push_back(f.at(rows[i].t_s, s.value(rows[i])));
    svg.polyline(pts, attr("stroke", s.color) + attr("stroke-width", "1") +
                          (s.dash.empty() ? "" : attr("stroke-dasharray", s.dash)));
  }
  svg.close("g");
}

// The panel's legend right of it: its heading, then a sample of each
// series' line with its name.
void history_legend(Svg& svg, const Frame& f, const HistoryPanel& hp) {
  const double x = HistoryLayout::kLegendX;
  svg.text(x, f.top + 12.0, hp.heading, attr("font-weight", "bold"));
  double yy = f.top + 30.0;
  for (const Series& s : hp.series) {
    svg.line(x, yy - 4.0, x + 24.0, yy - 4.0,
             attr("stroke", s.color) + attr("stroke-width", "1.5") +
                 (s.dash.empty() ? "" : attr("stroke-dasharray", s.dash)));
    svg.text(x + 30.0, yy, s.name, "");
    yy += 16.0;
  }
}

}  // namespace

std::string views_svg(const std::vector<TickRecord>& rows,
                      const sim::Case& the_case) {
  const std::string name = case_name(the_case);
  if (rows.empty()) return empty_document(name);
  const VmParams& vm = the_case.controller_params().vm;

  std::vector<Snapshot> snaps = {
      {"off_out_misaligned", "off", "RM off the path", nullptr, ""},
      {"on_misaligned_a", "on", "RM on the path", nullptr, ""},
  };
  for (Snapshot& s : snaps) find_snapshot(rows, the_case, &s);

  std::vector<Projection> projs;
  if (path_of(vm).planar) {
    // a planar path: one view, in its plane
    const bool device = vm.R_pivot.isApprox(Mat3::Identity(), 1e-12);
    const std::string plane = std::string(vm_kind_name(vm.kind)) + " plane";
    projs.push_back({"", plane + (device ? " (device x-y)" : " (pivot frame x-y)"),
                     vm.R_pivot.col(0), vm.R_pivot.col(1),
                     device ? "x_mm" : "x_pivot_mm",
                     device ? "y_mm" : "y_pivot_mm"});
  } else {
    projs.push_back({"xy", "x-y view", Vec3::UnitX(), Vec3::UnitY(), "x_mm",
                     "y_mm"});
    projs.push_back({"xz", "x-z view", Vec3::UnitX(), Vec3::UnitZ(), "x_mm",
                     "z_mm"});
    projs.push_back({"zy", "z-y view", Vec3::UnitZ(), Vec3::UnitY(), "z_mm",
                     "y_mm"});
  }

  const double cols = static_cast<double>(projs.size()) *
                      (projs.size() == 1 ? 2.0 : 1.0);
  const double nrows = projs.size() == 1 ? 1.0 : 2.0;
  const double width = cols * ViewLayout::kCellW + ViewLayout::kLegendW;
  const double height =
      ViewLayout::kHeader + nrows * ViewLayout::kCellH + 10.0;
  const std::string thesis_figures = vm_descriptor(vm.kind).thesis_figures;
  const std::string figures =
      thesis_figures.empty() ? "" : " (cf. thesis Figs " + thesis_figures + ")";
  Svg svg(width, height);
  svg.text(12.0, 20.0,
           name + ": the RM and the VM, off and on the path" + figures,
           attr("font-size", "14") + attr("font-weight", "bold"));
  for (std::size_t s = 0; s < snaps.size(); ++s) {
    for (std::size_t k = 0; k < projs.size(); ++k) {
      // the circle: snapshots side by side; three views: one row each
      const double col = static_cast<double>(projs.size() == 1 ? s : k);
      const double row = static_cast<double>(projs.size() == 1 ? 0 : s);
      view_panel(svg, col * ViewLayout::kCellW,
                 ViewLayout::kHeader + row * ViewLayout::kCellH, name,
                 snaps[s], projs[k], rows, vm);
    }
  }
  view_legend(svg, cols * ViewLayout::kCellW + 10.0,
              ViewLayout::kHeader + ViewLayout::kTop + 10.0, vm);
  return svg.finish();
}

std::string history_svg(const std::vector<TickRecord>& rows,
                        const sim::Case& the_case) {
  const std::string name = case_name(the_case);
  if (rows.empty()) return empty_document(name);

  const std::vector<HistoryPanel> panels = history_panels();
  const double legend_x = HistoryLayout::kLegendX;
  const double height = HistoryLayout::kHeight;
  Svg svg(HistoryLayout::kWidth, height);
  svg.text(12.0, 20.0,
           name + ": time history of error and force (cf. thesis Figs 4.3, "
                  "4.6, 4.19); device frame",
           attr("font-size", "14") + attr("font-weight", "bold"));

  const Frame time = history_time_axis(rows);
  const std::vector<std::size_t> idx = decimated(rows.size());
  const std::vector<ScriptSegment>& segs = the_case.script().segments();
  for (std::size_t k = 0; k < panels.size(); ++k) {
    const HistoryPanel& hp = panels[k];
    const Frame f = history_frame(time, k, hp, rows, idx);
    const std::string tag = std::string(1, static_cast<char>('a' + k));
    svg.open("g", attr("class", "history") + attr("id", "history-" + tag));
    history_segments(svg, f, k, segs);
    draw_axes(svg, f, "t (s)", hp.ylabel, k + 1 == panels.size());
    history_lines(svg, f, hp, rows, idx, tag);
    history_legend(svg, f, hp);
    svg.close("g");
  }
  const std::size_t every = idx.size() > 1 ? idx[1] - idx[0] : 1;
  svg.text(legend_x, height - 22.0,
           "plotted: 1 tick in " + std::to_string(every) + " of " +
               std::to_string(rows.size()),
           attr("fill", "#444") + attr("font-size", "10"));
  svg.text(legend_x, height - 8.0, "shaded / dashed: script segments",
           attr("fill", "#444") + attr("font-size", "10"));
  return svg.finish();
}

}  // namespace vmh::thesis
