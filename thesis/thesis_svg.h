// The thesis's own figures of a run, from its trace.csv: (a) theta_V and
// theta_R against time, and (b) the RM wrist centre's trajectory in the
// mechanism's plane coloured by time, over the VM's path (Wickham 2010,
// ch. 4 shows both for each case). One SVG 1.1 document per case.
//
// A time history of more rows than the plot is wide is drawn as a band
// from each pixel column's minimum to its maximum (with the column's mean
// as a line), not as every tick: the page stays small and nothing is
// hidden, since each column's extremes are drawn.
#ifndef VMHAPTICS_THESIS_THESIS_SVG_H_
#define VMHAPTICS_THESIS_THESIS_SVG_H_

#include <array>
#include <string>
#include <vector>

#include "thesis/force_field_svg.h"

namespace vmh::thesis {

// One trace row's angles and wrist centre: theta_v / theta_r hold the VM's
// joint values (1 for the circle, 3 for the sphere; rad, or the length
// unit for a surface's prismatic joints), p_mm the wrist centre (device
// frame, mm).
struct ThesisSample {
  double t_s = 0.0;
  std::vector<double> theta_v, theta_r;
  std::array<double, 3> p_mm{};
};

// trace.csv's t_s, theta_v_<k>, theta_r_<k> and p_{x,y,z}_mm columns, read
// by name. Throws std::runtime_error naming a missing column or a line
// that is not numbers.
std::vector<ThesisSample> thesis_samples_from_csv(const std::string& csv_text);

// The figure. `columns` is the time plots' width in pixel columns, the
// most bands a plot has.
std::string thesis_svg(const std::vector<ThesisSample>& samples,
                       const ForceFieldPath& path, int columns = 600);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_THESIS_SVG_H_
