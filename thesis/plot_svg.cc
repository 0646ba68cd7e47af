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

void view_panel(Svg& svg, double ox, double oy, const std::string& name,
                const Snapshot& snap, const Projection& proj,
                const std::vector<TickRecord>& rows, const VmParams& vm) {
  const std::string tag =
      std::string(snap.tag) + (proj.tag.empty() ? "" : "-" + proj.tag);
  auto u = [&](const Vec3& p) { return proj.a.dot(p); };
  auto v = [&](const Vec3& p) { return proj.b.dot(p); };
  const double L = vm.length_mm;
  // the path as the mechanism draws it (its drawing hook), mm
  const std::vector<PathPrimitive> path = path_of(vm).primitives;
  const std::vector<std::size_t> idx = decimated(rows.size());

  // what must be in view
  Bounds bu, bv;
  auto add = [&](const Vec3& p) {
    bu.add(u(p));
    bv.add(v(p));
  };
  add(vm.pivot_mm);
  for (const PathPrimitive& prim : path) {
    switch (prim.type) {
      case PathPrimitive::Type::kCircle:
      case PathPrimitive::Type::kSphere:
        bu.add(u(prim.centre) - prim.radius);
        bu.add(u(prim.centre) + prim.radius);
        bv.add(v(prim.centre) - prim.radius);
        bv.add(v(prim.centre) + prim.radius);
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
  const TickRecord* r = snap.row;
  if (r != nullptr) {
    const ControlOutput& o = r->out;
    add(o.p_rm_mm);
    add(o.x_v_mm);
    add(o.x_r_mm);
    add(o.p_rm_mm + kPlotStylusMm * o.axis_rm);
    add(o.p_rm_mm + kPlotForceMmPerN * o.force_device_N);
  }
  if (bu.empty() || bv.empty()) {
    bu = Bounds{-L, L};
    bv = Bounds{-L, L};
  }

  // a square of whole ticks around it, with a margin
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

  svg.open("g", attr("class", "panel") + attr("id", "panel-" + tag));
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

  svg.clip_rect("clip-" + tag, f.left, f.top, f.width, f.height);
  svg.open("g", attr("clip-path", "url(#clip-" + tag + ")"));
  const double pu = u(vm.pivot_mm), pv = v(vm.pivot_mm);
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
    trail.push_back(f.at(u(rows[i].out.p_rm_mm), v(rows[i].out.p_rm_mm)));
  }
  svg.polyline(trail, attr("stroke", "#a8a8a8") + attr("stroke-width", "0.8"));
  // the pivot
  svg.line(f.X(pu) - 4, f.Y(pv), f.X(pu) + 4, f.Y(pv), attr("stroke", "#000"));
  svg.line(f.X(pu), f.Y(pv) - 4, f.X(pu), f.Y(pv) + 4, attr("stroke", "#000"));

  if (r != nullptr) {
    const ControlOutput& o = r->out;
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

  const double left = 76.0, plot_w = 800.0, plot_h = 180.0, gap = 22.0;
  const double top0 = 58.0;
  const double legend_x = left + plot_w + 22.0;
  const double width = legend_x + 230.0;
  const double height = top0 + 3.0 * plot_h + 2.0 * gap + 52.0;
  Svg svg(width, height);
  svg.text(12.0, 20.0,
           name + ": time history of error and force (cf. thesis Figs 4.3, "
                  "4.6, 4.19); device frame",
           attr("font-size", "14") + attr("font-weight", "bold"));

  double t0 = rows.front().t_s, t1 = rows.back().t_s;
  if (!(t1 > t0)) t1 = t0 + 1e-3;
  const double tstep = nice_step(t1 - t0, 10.0);
  // end on a tick when the run nearly does (the last tick is at T - period)
  const double t_end = static_cast<double>(step_index_up(t1, tstep)) * tstep;
  if (t_end - t1 < 0.02 * (t1 - t0)) t1 = t_end;
  const std::vector<std::size_t> idx = decimated(rows.size());
  const std::vector<ScriptSegment>& segs = the_case.script().segments();

  for (std::size_t k = 0; k < panels.size(); ++k) {
    const HistoryPanel& hp = panels[k];
    Frame f;
    f.left = left;
    f.top = top0 + static_cast<double>(k) * (plot_h + gap);
    f.width = plot_w;
    f.height = plot_h;
    f.xlo = t0;
    f.xhi = t1;
    f.xstep = tstep;
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

    const std::string tag = std::string(1, static_cast<char>('a' + k));
    svg.open("g", attr("class", "history") + attr("id", "history-" + tag));
    // the script's segments: alternate shading, boundaries, names on top
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
    draw_axes(svg, f, "t (s)", hp.ylabel, k + 1 == panels.size());
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
    // legend
    svg.text(legend_x, f.top + 12.0, hp.heading, attr("font-weight", "bold"));
    double yy = f.top + 30.0;
    for (const Series& s : hp.series) {
      svg.line(legend_x, yy - 4.0, legend_x + 24.0, yy - 4.0,
               attr("stroke", s.color) + attr("stroke-width", "1.5") +
                   (s.dash.empty() ? "" : attr("stroke-dasharray", s.dash)));
      svg.text(legend_x + 30.0, yy, s.name, "");
      yy += 16.0;
    }
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
