// Hands the latest value of a plain-data T from one writer thread
// (the servo loop, the emulator's physics) to any number of readers without
// a lock: the writer never waits, a reader retries while a write is under
// way. A sequence lock, after Lameter, "Effective synchronization on Linux/
// NUMA systems" (2005), with the fences of Boehm, "Can seqlocks get along
// with programming language memory models?" (MSPC 2012).
#ifndef VMHAPTICS_DEVICE_SEQLOCK_H_
#define VMHAPTICS_DEVICE_SEQLOCK_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace vmh {

template <typename T>
class Seqlock {
  // T is copied byte by byte: plain data and fixed-size Eigen types, which
  // own no memory (Eigen's are not formally trivially copyable, but they
  // are trivially destructible; a std::vector or std::string is not)
  static_assert(std::is_trivially_destructible<T>::value,
                "Seqlock copies T byte by byte: it must own no memory");

 public:
  Seqlock() {
    for (auto& w : words_) w.store(0, std::memory_order_relaxed);
  }
  explicit Seqlock(const T& initial) : Seqlock() { write(initial); }

  // writer only; never blocks
  void write(const T& v) noexcept {
    const unsigned s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: a write is under way
    std::atomic_thread_fence(std::memory_order_release);
    copy_in(v);
    seq_.store(s + 2, std::memory_order_release);
  }

  // any thread: a consistent copy of the last value written. Spins while a
  // write is under way (a write is a memcpy: nanoseconds).
  T read() const noexcept {
    T out;
    while (!try_read(&out)) {
    }
    return out;
  }

  // one attempt: false if a write overlapped it (*out is then unspecified)
  bool try_read(T* out) const noexcept {
    const unsigned s0 = seq_.load(std::memory_order_acquire);
    if (s0 & 1u) return false;
    copy_out(out);
    std::atomic_thread_fence(std::memory_order_acquire);
    return seq_.load(std::memory_order_relaxed) == s0;
  }

  // how many writes so far
  unsigned writes() const noexcept {
    return seq_.load(std::memory_order_acquire) / 2u;
  }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

  // word-wise relaxed atomic copies, so that the overlapping read a retry
  // throws away is not a data race in the C++ memory model
  void copy_in(const T& v) noexcept {
    std::uint64_t tmp[kWords] = {};
    std::memcpy(tmp, &v, sizeof(T));
    for (std::size_t i = 0; i < kWords; ++i) {
      words_[i].store(tmp[i], std::memory_order_relaxed);
    }
  }
  void copy_out(T* out) const noexcept {
    std::uint64_t tmp[kWords];
    for (std::size_t i = 0; i < kWords; ++i) {
      tmp[i] = words_[i].load(std::memory_order_relaxed);
    }
    std::memcpy(static_cast<void*>(out), tmp, sizeof(T));
  }

  std::atomic<unsigned> seq_{0};
  std::atomic<std::uint64_t> words_[kWords];
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SEQLOCK_H_
