// SpscRing: first in first out, a full ring drops and counts, and a
// producer/consumer pair moves a million items in order.
#include "device/spsc_ring.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <thread>

namespace vmh {
namespace {

TEST(SpscRing, ZeroCapacityIsRefused) {
  EXPECT_THROW(SpscRing<int>(0), std::invalid_argument);
}

TEST(SpscRing, FirstInFirstOut) {
  SpscRing<int> r(4);
  EXPECT_EQ(r.capacity(), 4u);
  int v = -1;
  EXPECT_FALSE(r.pop(&v));
  for (int i = 1; i <= 3; ++i) EXPECT_TRUE(r.push(i));
  for (int i = 1; i <= 3; ++i) {
    ASSERT_TRUE(r.pop(&v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(r.pop(&v));
  EXPECT_EQ(r.dropped(), 0);
}

TEST(SpscRing, FullRingDropsAndCounts) {
  SpscRing<int> r(4);
  for (int i = 1; i <= 4; ++i) EXPECT_TRUE(r.push(i));
  EXPECT_FALSE(r.push(5));
  EXPECT_FALSE(r.push(6));
  EXPECT_EQ(r.dropped(), 2);
  int v = 0;
  for (int i = 1; i <= 4; ++i) {  // the dropped ones are not there
    ASSERT_TRUE(r.pop(&v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(r.pop(&v));
  // room again, and the order holds across the wrap-around
  for (int round = 0; round < 5; ++round) {
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(r.push(10 * round + i));
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(r.pop(&v));
      EXPECT_EQ(v, 10 * round + i);
    }
  }
  EXPECT_EQ(r.dropped(), 2);
}

TEST(SpscRing, TwoThreadsMoveAMillionItemsInOrder) {
  constexpr long kItems = 1000000;
  SpscRing<long> r(1024);
  long refused = 0;  // pushes the producer saw fail (and then retried)
  std::thread producer([&] {
    for (long i = 0; i < kItems; ++i) {
      while (!r.push(i)) {
        ++refused;
        std::this_thread::yield();
      }
    }
  });
  long expected = 0;
  long out_of_order = 0;
  long v = -1;
  while (expected < kItems) {
    if (r.pop(&v)) {
      if (v != expected) ++out_of_order;
      expected = v + 1;
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();
  EXPECT_EQ(out_of_order, 0);
  EXPECT_EQ(expected, kItems);
  EXPECT_FALSE(r.pop(&v));
  EXPECT_EQ(r.dropped(), refused);
}

}  // namespace
}  // namespace vmh
