#include "core/first_touch.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace dispex {
namespace {

// Large enough that the new storage is touched (kFirstTouchBytes), not only reserved.
constexpr std::size_t kLarge = 3 * kFirstTouchBytes / sizeof(std::int32_t) + 123;

TEST(FirstTouch, ReserveTouchedKeepsTheElementsAndTouchesOnlyBeyondThem) {
  std::vector<std::int32_t> v(1000);
  std::iota(v.begin(), v.end(), 1);
  const std::int32_t* before = v.data();
  ReserveTouched(v, kLarge);
  EXPECT_GE(v.capacity(), kLarge);
  ASSERT_EQ(v.size(), 1000u);
  EXPECT_NE(v.data(), before);  // grown: the elements were moved into the new storage
  for (std::size_t k = 0; k < v.size(); ++k) ASSERT_EQ(v[k], static_cast<std::int32_t>(k + 1));
  v.resize(kLarge, 5);
  EXPECT_EQ(v[999], 1000);
  EXPECT_EQ(v[1000], 5);
  EXPECT_EQ(v.back(), 5);
  // Room already there: nothing is reallocated.
  const std::int32_t* grown = v.data();
  ReserveTouched(v, kLarge / 2);
  EXPECT_EQ(v.data(), grown);
  EXPECT_EQ(v.size(), kLarge);
}

TEST(FirstTouch, AssignTouchedReplacesTheContents) {
  std::vector<std::uint16_t> small(7, 9);
  AssignTouched(small, 3, std::uint16_t{2});
  EXPECT_EQ(small, std::vector<std::uint16_t>(3, 2));
  std::vector<float> large(10, 1.0f);
  AssignTouched(large, kLarge, -0.5f);
  ASSERT_EQ(large.size(), kLarge);
  for (float x : large) ASSERT_EQ(x, -0.5f);
}

}  // namespace
}  // namespace dispex
