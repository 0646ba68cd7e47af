// The thesis's figures (ch. 4) drawn from a run, as standalone SVG 1.1
// documents, with no library beyond the standard one.
//
// views_svg: the "error outside path" / "error on path" views (Figs 4.1,
// 4.2, 4.13-4.18). Two snapshots, each the row nearest the middle of the
// settled half of a script segment: "off_out_misaligned" (the RM held off
// the path, stylus misaligned) and "on_misaligned_a" (on the path, stylus
// misaligned). Each shows the VM's path, the RM wrist-centre trajectory of
// the whole run, the RM point p, the red line pivot -> X(theta_V), the green
// line pivot -> X(theta_R), the stylus axis at p and the commanded force as
// a magenta arrow from p with its in-view components. The circle is drawn in
// its own plane (the pivot frame's x-y: device x-y for the thesis's cases),
// the sphere and the surface in three projections (x-y, x-z, z-y). Device
// frame, mm, equal aspect.
//
// history_svg: the time histories (Figs 4.3, 4.6, 4.19): p - X(theta_V) and
// the distance to the path, p - X(theta_R), and the commanded force, over a
// shared time axis with the script's segments marked. Each polyline keeps
// every k-th row so that it has at most kPlotMaxPoints (+ the last row).
//
// Elements a reader (or a test) can find: each panel is a <g class="panel"
// id="panel-TAG">, its path outline id="path-TAG", its force arrow shaft
// id="force-TAG" (a <line> from p to p + kPlotForceMmPerN F in the panel's
// pixels), where TAG is "off"/"on" for the circle and "off-xy", "off-xz",
// "off-zy", ... for three projections.
#ifndef VMHAPTICS_THESIS_PLOT_SVG_H_
#define VMHAPTICS_THESIS_PLOT_SVG_H_

#include <cstddef>
#include <string>
#include <vector>

#include "device/tick_record.h"
#include "sim/cases/case.h"

namespace vmh::thesis {

// the views draw the force F as an arrow kPlotForceMmPerN x |F| mm long
inline constexpr double kPlotForceMmPerN = 10.0;
// length of the stylus-axis segment drawn at p
inline constexpr double kPlotStylusMm = 15.0;
// polylines keep at most this many rows, plus the run's last one
inline constexpr std::size_t kPlotMaxPoints = 2000;

std::string views_svg(const std::vector<TickRecord>& rows,
                      const sim::Case& the_case);
std::string history_svg(const std::vector<TickRecord>& rows,
                        const sim::Case& the_case);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_PLOT_SVG_H_
