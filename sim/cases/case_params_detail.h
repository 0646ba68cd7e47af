// Helpers shared by the case-parameter table (case_fields.cc) and its loader
// (case_params.cc); not part of the public interface.
#ifndef VMHAPTICS_SIM_CASES_CASE_PARAMS_DETAIL_H_
#define VMHAPTICS_SIM_CASES_CASE_PARAMS_DETAIL_H_

#include <string>

namespace vmh::sim::detail {

// the position of `text` in a ", "-separated list of words; -1 if absent
int word_index(const char* words, const std::string& text);

// a number as %.9g, for messages and the docs
std::string format_number(double v);

}  // namespace vmh::sim::detail

#endif  // VMHAPTICS_SIM_CASES_CASE_PARAMS_DETAIL_H_
