#include "tests/support/alloc_counter.h"

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VMH_ALLOC_COUNTER_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define VMH_ALLOC_COUNTER_ASAN 1
#endif

namespace {

std::atomic<bool> g_armed{false};
std::atomic<std::size_t> g_count{0};
std::atomic<const void*> g_kept{nullptr};

inline void count_one() {
  if (g_armed.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace

#ifndef VMH_ALLOC_COUNTER_ASAN
// glibc's own allocator under its exported names: the replacements below
// count and pass every call on to it
extern "C" {
void* __libc_malloc(std::size_t n);
void* __libc_calloc(std::size_t n, std::size_t size);
void* __libc_realloc(void* p, std::size_t n);
void* __libc_memalign(std::size_t align, std::size_t n);
void __libc_free(void* p);

void* malloc(std::size_t n) {
  count_one();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  count_one();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  count_one();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* memalign(std::size_t align, std::size_t n) {
  count_one();
  return __libc_memalign(align, n);
}
void* aligned_alloc(std::size_t align, std::size_t n) {
  count_one();
  return __libc_memalign(align, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  // a power of two and a multiple of sizeof(void*), as POSIX asks
  if (align < sizeof(void*) || (align & (align - 1)) != 0) return EINVAL;
  count_one();
  void* p = __libc_memalign(align, n);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
}  // extern "C"
#endif

namespace {

// operator new: counted here under ASan, else by the malloc it calls
void* new_alloc(std::size_t n, std::size_t align) {
#ifdef VMH_ALLOC_COUNTER_ASAN
  count_one();
#endif
  if (n == 0) n = 1;
  void* p = nullptr;
  if (align <= alignof(std::max_align_t)) {
    p = std::malloc(n);
  } else if (posix_memalign(&p, align, n) != 0) {
    p = nullptr;
  }
  return p;
}

}  // namespace

namespace vmh::testing {

#ifdef VMH_ALLOC_COUNTER_ASAN
const bool kCountsMalloc = false;
#else
const bool kCountsMalloc = true;
#endif

AllocationScope::AllocationScope() {
  g_count.store(0);
  g_armed.store(true);
}

AllocationScope::~AllocationScope() { g_armed.store(false); }

std::size_t AllocationScope::count() const { return g_count.load(); }

void keep_alive(const void* p) { g_kept.store(p, std::memory_order_relaxed); }

}  // namespace vmh::testing

// replacements of the global allocation functions ([new.delete])
void* operator new(std::size_t n) {
  if (void* p = new_alloc(n, 0)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = new_alloc(n, 0)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t a) {
  if (void* p = new_alloc(n, static_cast<std::size_t>(a))) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) {
  if (void* p = new_alloc(n, static_cast<std::size_t>(a))) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return new_alloc(n, 0);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return new_alloc(n, 0);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
