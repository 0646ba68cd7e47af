// What the sensitivity study's outputs (sensitivity_output.cc) and its
// shards' files (sensitivity_shards.cc) share, internal to studies/: a
// number or null, and a row of the table as JSON and back.
#ifndef VMHAPTICS_STUDIES_SENSITIVITY_DETAIL_H_
#define VMHAPTICS_STUDIES_SENSITIVITY_DETAIL_H_

#include <nlohmann/json.hpp>

#include <cmath>

#include "studies/sensitivity_study.h"

namespace vmh::studies::detail {

// x, or null where it is not finite (JSON has no NaN)
inline nlohmann::ordered_json sens_number_or_null(double x) {
  using Json = nlohmann::ordered_json;
  return std::isfinite(x) ? Json(x) : Json();
}

// A row as sensitivity.json's `parameters` and a partial file's options
// give it: name, kind, field (null for none), scale, the choices or low and
// high, unit, source, optional.
nlohmann::ordered_json parameter_json(const SweepParameter& p);
// And back; std::runtime_error (or nlohmann's) on a row that is not one.
SweepParameter parameter_from(const nlohmann::json& j);

}  // namespace vmh::studies::detail

#endif  // VMHAPTICS_STUDIES_SENSITIVITY_DETAIL_H_
