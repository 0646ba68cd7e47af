// A VM's path in an SVG view, from its drawing hook
// (VirtualMechanism::path_primitives, controller/virtual_mechanism.h): the
// one place where the figures (views.svg, the force field, the thesis-style
// figure) turn the primitives into elements, so a new mechanism draws in
// all of them without a change here.
#ifndef VMHAPTICS_THESIS_PATH_SVG_H_
#define VMHAPTICS_THESIS_PATH_SVG_H_

#include <functional>
#include <string>
#include <vector>

#include "controller/virtual_mechanism.h"

namespace vmh::thesis {

// A view: the device-frame unit vectors drawn rightward (a) and upward (b),
// the maps from view coordinates (mm) to pixels, the scale, and the frame
// (view coordinates, mm) that lines are cut to
struct PathView {
  Vec3 a = Vec3::UnitX();
  Vec3 b = Vec3::UnitY();
  std::function<double(double)> X, Y;
  double px_per_mm = 1.0;
  double lo[2] = {-1.0, -1.0};
  double hi[2] = {1.0, 1.0};
};

// A square view `span` mm wide centred on (c0, c1), view coordinates
PathView square_view(const Vec3& a, const Vec3& b,
                     std::function<double(double)> X,
                     std::function<double(double)> Y, double px_per_mm,
                     double c0, double c1, double span);

// The elements: a circle or a sphere's outline as a circle (a circle is
// one only in its own plane's view, where the figures draw it); a line as a
// line across the frame (a dot where it is seen end-on); a plane seen
// edge-on as two dashed lines, the handle's path `radius` to either side
// (nothing where it is not edge-on). `id` goes on the first element of a
// circle or line ("" for none); `style` on every stroke.
std::string path_elements(const std::vector<PathPrimitive>& path,
                          const PathView& view, const std::string& id,
                          const std::string& style);

// A VM's path as the figures need it, device frame, mm: its primitives,
// whether it lies in its pivot frame's x-y plane (then one view, that
// plane), and the legend's label for it
struct VmPath {
  std::vector<PathPrimitive> primitives;
  bool planar = false;
  std::string label;
};

// The path of a VM of a registered kind by name (a case's `vm_kind`) with
// its pivot (device frame, mm), length L (mm) and pivot frame. Throws
// std::runtime_error for a kind not registered, naming the ones that are;
// std::invalid_argument for a bad pivot or length.
VmPath vm_path_mm(const std::string& kind, const Vec3& pivot_mm,
                  double length_mm, const Mat3& R_pivot = Mat3::Identity());

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_PATH_SVG_H_
