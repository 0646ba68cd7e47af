// How the bring-up comparisons write a number into a message or a summary
// line: `digits` significant digits, as std::ostream writes them (0.1234,
// 1.23e-05). Internal to bringup/.
#ifndef VMHAPTICS_BRINGUP_COMPARE_TEXT_H_
#define VMHAPTICS_BRINGUP_COMPARE_TEXT_H_

#include <sstream>
#include <string>

namespace vmh::bringup::detail {

inline std::string significant(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace vmh::bringup::detail

#endif  // VMHAPTICS_BRINGUP_COMPARE_TEXT_H_
