#include "extract/box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>

namespace dispex::extract {
namespace {

// The definition: closed intervals that overlap on every axis.
bool MeetsByAxes(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k) {
    if (!(a.lower[k] <= b.upper[k] && b.lower[k] <= a.upper[k])) return false;
  }
  return true;
}

TEST(Box, MeetsAsEveryAxisOverlaps) {
  // Bounds from a few values, so that touching and equal bounds are common, and NaN.
  std::mt19937 random(7);
  const float values[] = {-2.0f, -1.0f, 0.0f, 0.5f, 1.0f, 3.0f, INFINITY, -INFINITY, NAN};
  std::uniform_int_distribution<int> pick(0, 8);
  int met = 0, checked = 0;
  for (int n = 0; n < 200000; ++n) {
    Box a, b;
    for (int k = 0; k < 3; ++k) {
      a.lower[k] = values[pick(random) % 6];
      a.upper[k] = values[pick(random) % 6];
      b.lower[k] = values[pick(random) % 6];
      b.upper[k] = values[pick(random) % 6];
      // Mostly proper boxes; one in four keeps a reversed (empty) axis.
      if (n % 4 != 0) {
        if (a.lower[k] > a.upper[k]) std::swap(a.lower[k], a.upper[k]);
        if (b.lower[k] > b.upper[k]) std::swap(b.lower[k], b.upper[k]);
      }
    }
    // Now and then an infinite or NaN bound, one at a time at every position.
    if (n % 7 == 0) {
      const int at = n / 7 % 12;
      float* bounds[] = {&a.lower[0], &a.lower[1], &a.lower[2], &a.upper[0],
                         &a.upper[1], &a.upper[2], &b.lower[0], &b.lower[1],
                         &b.lower[2], &b.upper[0], &b.upper[1], &b.upper[2]};
      *bounds[at] = values[6 + n / 84 % 3];
    }
    const bool expected = MeetsByAxes(a, b);
    ASSERT_EQ(a.Meets(b), expected) << "case " << n;
    ASSERT_EQ(b.Meets(a), expected) << "case " << n;
    met += expected;
    ++checked;
  }
  // Both answers are common.
  EXPECT_GT(met, checked / 20);
  EXPECT_LT(met, checked - checked / 20);
}

TEST(Box, TouchingBoxesMeet) {
  const Box a{{0, 0, 0}, {1, 1, 1}};
  EXPECT_TRUE(a.Meets(Box{{1, 1, 1}, {2, 2, 2}}));
  EXPECT_TRUE(a.Meets(Box{{-1, 0.5f, 1}, {0, 0.5f, 3}}));
  EXPECT_FALSE(a.Meets(Box{{1, 1, std::nextafter(1.0f, 2.0f)}, {2, 2, 2}}));
  EXPECT_FALSE(a.Meets(Box{{-1, -1, -1}, {std::nextafter(0.0f, -1.0f), 1, 1}}));
}

}  // namespace
}  // namespace dispex::extract
