// Force-included (-include) into the allocation test's build of the
// controller sources: an Eigen assertion, such as a heap allocation while
// EIGEN_RUNTIME_NO_MALLOC forbids it, throws instead of aborting, so the test
// can report it.
#ifndef VMHAPTICS_TESTS_SUPPORT_EIGEN_ASSERT_THROWS_H_
#define VMHAPTICS_TESTS_SUPPORT_EIGEN_ASSERT_THROWS_H_

#include <stdexcept>

namespace vmh::testing {
struct EigenAssertFailure : std::logic_error {
  using std::logic_error::logic_error;
};
}  // namespace vmh::testing

#define eigen_assert(x)                                     \
  do {                                                      \
    if (!(x)) throw ::vmh::testing::EigenAssertFailure(#x); \
  } while (false)

#endif  // VMHAPTICS_TESTS_SUPPORT_EIGEN_ASSERT_THROWS_H_
