// A number as text with `digits` significant digits, as std::ostream
// writes it (0.1234, 1.23e-05): for messages and summary lines, where a
// reader compares it, not a program (for text a program reads back, see
// studies/study_numbers.h's exact()).
#ifndef VMHAPTICS_OUTPUT_NUMBER_TEXT_H_
#define VMHAPTICS_OUTPUT_NUMBER_TEXT_H_

#include <sstream>
#include <string>

namespace vmh::output {

inline std::string significant(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace vmh::output

#endif  // VMHAPTICS_OUTPUT_NUMBER_TEXT_H_
