// Counts heap allocations made through operator new while armed, so a test
// can prove that a call allocates nothing. Eigen's own allocations go
// through malloc and are caught by EIGEN_RUNTIME_NO_MALLOC instead.
#ifndef VMHAPTICS_TESTS_SUPPORT_ALLOC_COUNTER_H_
#define VMHAPTICS_TESTS_SUPPORT_ALLOC_COUNTER_H_

#include <cstddef>

namespace vmh::testing {

// Allocations counted since the scope began; counting stops when it ends.
class AllocationScope {
 public:
  AllocationScope();
  ~AllocationScope();
  AllocationScope(const AllocationScope&) = delete;
  AllocationScope& operator=(const AllocationScope&) = delete;
  std::size_t count() const;
};

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_ALLOC_COUNTER_H_
