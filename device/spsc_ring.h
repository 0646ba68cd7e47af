// A bounded queue from one producer thread to one consumer thread, without
// locks or allocation after construction: the servo loop pushes one sample
// per tick, a recorder thread pops them and writes the trace. When the
// consumer falls behind and the ring is full, push() drops the sample and
// counts it, rather than making the servo loop wait.
#ifndef VMHAPTICS_DEVICE_SPSC_RING_H_
#define VMHAPTICS_DEVICE_SPSC_RING_H_

#include <atomic>
#include <cstddef>
#include <memory>
#include <stdexcept>

namespace vmh {

template <typename T>
class SpscRing {
 public:
  // room for `capacity` items; throws std::invalid_argument for 0
  explicit SpscRing(std::size_t capacity)
      : size_(capacity + 1), slots_(new T[capacity + 1]) {
    if (capacity == 0) throw std::invalid_argument("SpscRing: capacity 0");
  }

  // producer only. false (and one more dropped()) when full.
  bool push(const T& v) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t next = head + 1 == size_ ? 0 : head + 1;
    if (next == tail_.load(std::memory_order_acquire)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[head] = v;
    head_.store(next, std::memory_order_release);
    return true;
  }

  // consumer only. false when empty.
  bool pop(T* out) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    *out = slots_[tail];
    tail_.store(tail + 1 == size_ ? 0 : tail + 1, std::memory_order_release);
    return true;
  }

  std::size_t capacity() const noexcept { return size_ - 1; }
  // items the producer could not push because the ring was full
  long dropped() const noexcept {
    return dropped_.load(std::memory_order_relaxed);
  }

 private:
  const std::size_t size_;
  std::unique_ptr<T[]> slots_;
  alignas(64) std::atomic<std::size_t> head_{0};  // next slot to write
  alignas(64) std::atomic<std::size_t> tail_{0};  // next slot to read
  std::atomic<long> dropped_{0};
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SPSC_RING_H_
