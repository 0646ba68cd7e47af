// The modelling spread beside the numerical error (issue 16, item 5): how
// far the RMS path error moves across the sensitivity study's sweep of what
// is uncertain (sensitivity.json's modelling_spread), read back so that the
// precision study can show it next to each integrator's error.
//
// Why the two compare: the path error is a distance from the path, so a
// trajectory error e moves it by at most e (triangle inequality). A setting
// whose RMS error vs the reference is far below the modelling spread is
// accurate enough for what the model knows; one near it is not.
#ifndef VMHAPTICS_STUDIES_MODELLING_SPREAD_H_
#define VMHAPTICS_STUDIES_MODELLING_SPREAD_H_

#include <nlohmann/json.hpp>

#include <string>

#include "output/svg_chart.h"

namespace vmh::studies {

struct ModellingSpread {
  bool present = false;
  std::string source;      // the sensitivity.json it came from
  std::string case_name;
  std::string sweep_id;
  std::string over;        // "sample" or "one_at_a_time"
  int points = 0;
  double nominal_mm = 0.0;  // RMS path error at the nominal point
  double min_mm = 0.0;
  double max_mm = 0.0;
  double spread_mm = 0.0;   // max - min
};

// The case's spread from sensitivity.json (a file, or a folder holding
// one). Throws SimError naming the file when it cannot be read or has no
// such case.
ModellingSpread read_modelling_spread(const std::string& path,
                                      const std::string& case_name);

// The spread and, against a numerical error (mm; NaN: none), their ratio
// and which dominates.
nlohmann::ordered_json modelling_spread_json(const ModellingSpread& s,
                                             double numerical_error_mm);

// A horizontal dashed line at the spread across the chart's x range (the
// span of its series).
void add_modelling_spread(output::Chart* chart, const ModellingSpread& s);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_MODELLING_SPREAD_H_
