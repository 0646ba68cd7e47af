// The commanded force along the path, as the thesis draws it in ch. 4
// (docs/sources.md §2): arrows of the force F at points of the RM
// wrist-centre trajectory sampled evenly along its length, over the VM's path, in the
// mechanism's plane for the circle (the pivot frame's x-y, the device's x-y
// for the thesis's cases) and in three projections (x-y, x-z, z-y) for the
// sphere and the surface. Device frame, mm; the arrows' scale (mm per N) is
// chosen so that the largest is a fixed share of the panel and is printed
// under the title.
//
// It reads what trace.csv holds, so that the report can draw it for a run
// finished earlier as well as for one just made.
//
// Elements a reader (or a test) can find: each panel is a <g class="panel"
// id="ff-TAG"> (TAG "xy", "xz" or "zy") whose data-axes="a,b" names the
// device axes drawn across and up; each arrow's shaft is a <line class="force"
// data-t-s="T"> from p to p + scale F projected, in the panel's pixels (y
// down), T the trace row's t_s.
#ifndef VMHAPTICS_THESIS_FORCE_FIELD_SVG_H_
#define VMHAPTICS_THESIS_FORCE_FIELD_SVG_H_

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "thesis/path_svg.h"

namespace vmh::thesis {

// one trace row's wrist centre and commanded force (device frame)
struct ForceSample {
  double t_s = 0.0;
  std::array<double, 3> p_mm{};
  std::array<double, 3> F_N{};
};

// the VM's path as the case's parameters give it
struct ForceFieldPath {
  std::string vm_kind;  // a registered name: "circle", "sphere", ...
  std::array<double, 3> pivot_mm{};
  double length_mm = 0.0;  // the VM's length L
};

// The VM's path of `path` as the figures draw it (thesis/path_svg.h);
// empty where length_mm is not > 0. Throws std::runtime_error for a kind
// not registered.
VmPath vm_path_of(const ForceFieldPath& path);

// arrows drawn by default
inline constexpr std::size_t kForceFieldArrows = 72;

// The figure as a standalone SVG 1.1 document. `arrows` samples are taken
// evenly along the trajectory's length (where the hand holds still, evenly
// in time would pile them up); one whose projected force would be shorter than 2 px is
// left out (it shows no direction). Empty `samples`: a document that says
// so.
std::string force_field_svg(const std::vector<ForceSample>& samples,
                            const ForceFieldPath& path,
                            std::size_t arrows = kForceFieldArrows);

// trace.csv's text (docs/outputs.md) to samples: the columns t_s,
// p_x_mm..p_z_mm and F_x_N..F_z_N. Throws std::runtime_error naming a
// missing column or the line of a short or non-numeric row.
std::vector<ForceSample> force_samples_from_csv(const std::string& csv_text);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_FORCE_FIELD_SVG_H_
