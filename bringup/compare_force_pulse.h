// compare's force-direction check (bringup/compare_force.h), the part
// that reads a motor test: the pulse found in the recording and the state
// the prediction starts from (compare_force_pulse.cc). Not part of the
// public interface.
#ifndef VMHAPTICS_BRINGUP_COMPARE_FORCE_PULSE_H_
#define VMHAPTICS_BRINGUP_COMPARE_FORCE_PULSE_H_

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "bringup/compare_force.h"
#include "bringup/reading_map.h"
#include "bringup/recording.h"
#include "bringup/response_sim.h"
#include "controller/types.h"
#include "output/number_text.h"

namespace vmh::bringup::detail {

inline const double kNan = std::nan("");

// three significant digits unless asked for more
inline std::string force_fmt(double v, int digits = 3) {
  return output::significant(v, digits);
}

// The recording's rows from the sample before the pulse to its settling:
// times, torques sent (NaN as zero), and the true device angles where the
// reading was good.
struct PulseWindow {
  int motor = 0;           // 1..3
  double t_start_s = 0.0;  // the pulse's first row
  double pulse_s = 0.0;
  double t_end_s = 0.0;       // the last row compared
  std::size_t sim_start = 0;  // index into the vectors below
  std::vector<double> t_s;
  std::vector<Vec3> tau_Nm;
  std::vector<Joints> q;  // true device angles (NaN when not good)
  std::vector<bool> good;
};

// Finds the pulse of the recording's pulsed motor (meta "motor", else the
// one sent a torque most often) and fills w: empty reason when found,
// otherwise why there is nothing to compare. Throws std::invalid_argument
// for a motor in meta.json that is not 1, 2 or 3.
std::string find_pulse(const Recording& rec, const ReadingMap& map,
                       const ForceOptions& o, PulseWindow* w);

// the samples from the simulation's start, as ResponseSimulator takes them
ResponseInput response_input(const PulseWindow& w, const ForceOptions& o);

}  // namespace vmh::bringup::detail

#endif  // VMHAPTICS_BRINGUP_COMPARE_FORCE_PULSE_H_
