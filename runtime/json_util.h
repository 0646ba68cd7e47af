// Eigen values as JSON arrays: vectors as lists, matrices as lists of rows;
// the time stamp the outputs carry.
#ifndef VMHAPTICS_RUNTIME_JSON_UTIL_H_
#define VMHAPTICS_RUNTIME_JSON_UTIL_H_

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

namespace vmh {

// keys stay in the order the program writes them
using Json = nlohmann::ordered_json;

// JSON text for people and programs alike: one key per line, and arrays of
// numbers (or of rows of numbers) on one line each.
std::string dump_readable(const Json& j);

// now, UTC, ISO 8601 to the second ("2026-11-23T16:04:02Z"): the date_utc
// of meta.json, of stored calibrations and of the report's header
std::string utc_now();

template <typename Derived>
Json to_json_vector(const Eigen::MatrixBase<Derived>& v) {
  Json out = Json::array();
  // + 0.0 prints -0.0 as 0.0
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i) + 0.0);
  return out;
}

template <typename Derived>
Json to_json_rows(const Eigen::MatrixBase<Derived>& m) {
  Json out = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c) + 0.0);
    out.push_back(std::move(row));
  }
  return out;
}

}  // namespace vmh

#endif  // VMHAPTICS_RUNTIME_JSON_UTIL_H_
