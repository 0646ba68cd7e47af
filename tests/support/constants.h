// Constants the tests share. One definition, so that the tests of a
// module compile together (tests/CMakeLists.txt: a unity build) without
// each source's own copy colliding with another's.
#ifndef VMHAPTICS_TESTS_SUPPORT_CONSTANTS_H_
#define VMHAPTICS_TESTS_SUPPORT_CONSTANTS_H_

namespace vmh::testing {
inline constexpr double kPi = 3.14159265358979323846;
}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_CONSTANTS_H_
