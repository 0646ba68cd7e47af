#include "thesis/path_svg.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <memory>
#include <stdexcept>

#include "controller/vm_registry.h"
#include "output/svg_text.h"

namespace vmh::thesis {

using output::svg::attr;
using output::svg::px;

PathView square_view(const Vec3& a, const Vec3& b,
                     std::function<double(double)> X,
                     std::function<double(double)> Y, double px_per_mm,
                     double c0, double c1, double span) {
  PathView v;
  v.a = a;
  v.b = b;
  v.X = std::move(X);
  v.Y = std::move(Y);
  v.px_per_mm = px_per_mm;
  v.lo[0] = c0 - span / 2;
  v.lo[1] = c1 - span / 2;
  v.hi[0] = c0 + span / 2;
  v.hi[1] = c1 + span / 2;
  return v;
}

std::string path_elements(const std::vector<PathPrimitive>& path,
                          const PathView& v, const std::string& id,
                          const std::string& style) {
  const auto U = [&v](const Vec3& p) { return v.a.dot(p); };
  const auto V = [&v](const Vec3& p) { return v.b.dot(p); };
  const std::string id_attr = id.empty() ? "" : attr("id", id);
  // the line through c along (du, dv) in the view, cut to the frame; ""
  // where it misses it
  const auto line = [&](const Vec3& c, double du, double dv,
                        const std::string& attrs) -> std::string {
    const double p[2] = {U(c), V(c)}, d[2] = {du, dv};
    double t0 = -1e300, t1 = 1e300;
    for (int k = 0; k < 2; ++k) {
      if (std::abs(d[k]) < 1e-12) {
        if (p[k] < v.lo[k] || p[k] > v.hi[k]) return "";
        continue;
      }
      double a = (v.lo[k] - p[k]) / d[k], b = (v.hi[k] - p[k]) / d[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (!(t0 < t1)) return "";
    return "<line" + attr("x1", px(v.X(p[0] + t0 * du))) +
           attr("y1", px(v.Y(p[1] + t0 * dv))) +
           attr("x2", px(v.X(p[0] + t1 * du))) +
           attr("y2", px(v.Y(p[1] + t1 * dv))) + attrs + "/>\n";
  };
  std::string g;
  for (const PathPrimitive& prim : path) {
    switch (prim.type) {
      case PathPrimitive::Type::kCircle:
      case PathPrimitive::Type::kSphere:
        g += "<circle" + attr("cx", px(v.X(U(prim.centre)))) +
             attr("cy", px(v.Y(V(prim.centre)))) +
             attr("r", px(prim.radius * v.px_per_mm)) + id_attr +
             attr("fill", "none") + style + "/>\n";
        break;
      case PathPrimitive::Type::kLine: {
        const double du = U(prim.u), dv = V(prim.u);
        if (std::hypot(du, dv) < 1e-9) {  // seen end-on: a dot
          g += "<circle" + attr("cx", px(v.X(U(prim.centre)))) +
               attr("cy", px(v.Y(V(prim.centre)))) + attr("r", "3") +
               id_attr + attr("fill", "#555") + "/>\n";
        } else {
          g += line(prim.centre, du / std::hypot(du, dv),
                    dv / std::hypot(du, dv), id_attr + style);
        }
        break;
      }
      case PathPrimitive::Type::kPlane: {
        const Vec3 n = prim.u.cross(prim.v);
        if ((n - v.a.dot(n) * v.a - v.b.dot(n) * v.b).norm() >= 1e-6) break;
        for (double side : {-1.0, 1.0}) {
          g += line(prim.centre + side * prim.radius * n, -V(n), U(n),
                    style + attr("stroke-dasharray", "6 3"));
        }
        break;
      }
    }
  }
  return g;
}

VmPath vm_path_mm(const std::string& kind, const Vec3& pivot_mm,
                  double length_mm, const Mat3& R_pivot) {
  const VmDescriptor* d = find_vm(kind);
  if (d == nullptr) {
    throw std::runtime_error("unknown vm_kind '" + kind + "' (expected one of: " +
                             vm_kind_names() + ")");
  }
  VmMount mount;
  mount.origin = pivot_mm;
  mount.R = R_pivot;
  const std::unique_ptr<VirtualMechanism> vm = d->make(mount, length_mm);
  VmPath out;
  out.primitives = vm->path_primitives();
  out.planar = vm->planar();
  out.label = d->path_label;
  return out;
}

}  // namespace vmh::thesis
