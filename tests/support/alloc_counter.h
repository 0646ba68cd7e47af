// Counts heap allocations while armed, so a test can prove that a call
// allocates nothing. Both doors to the heap are counted: operator new
// (replaced, [new.delete]) and the C allocator, malloc, calloc, realloc,
// posix_memalign, aligned_alloc and memalign (replaced as glibc allows,
// "Replacing malloc" in its manual), which is where Eigen's dynamic
// matrices come from. The program's own objects are counted as they are
// built (-O3, NDEBUG): what is measured is the code users run.
//
// Under AddressSanitizer, whose runtime owns malloc, only operator new is
// counted (kCountsMalloc is false).
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

// whether malloc and its family are counted in this build
extern const bool kCountsMalloc;

// Hands p to code the compiler cannot see into, so that an allocation a
// test makes on purpose is not removed as unused (C++14 lets a compiler
// leave out a new/delete or malloc/free pair whose memory nothing reads).
void keep_alive(const void* p);

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_ALLOC_COUNTER_H_
