// Constants the tests share: the library's own (controller/types.h), named
// in vmh::testing once, so that the tests of a module compile together
// (tests/CMakeLists.txt: a unity build) without each source's own copy
// colliding with another's.
#ifndef VMHAPTICS_TESTS_SUPPORT_CONSTANTS_H_
#define VMHAPTICS_TESTS_SUPPORT_CONSTANTS_H_

#include "controller/types.h"

namespace vmh::testing {
using constants::kPi;
}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_CONSTANTS_H_
