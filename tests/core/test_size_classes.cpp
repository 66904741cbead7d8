// Size classes (core/size_classes.hpp): the class boundaries at the halvings of the largest
// size, empty classes left out, zero and the smallest sizes in the last class.
#include "core/size_classes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace kairos {
namespace {

TEST(SizeClasses, HalvingsOfTheLargestBoundTheClasses) {
  // (0.5, 1] | (0.25, 0.5] | empty (0.125, 0.25] | (0.0625, 0.125]
  const SizeClasses c = size_classes({1.0, 0.5, 0.51, 0.26, 0.3, 0.1, 0.125});
  ASSERT_EQ(c.count(), 3u);
  EXPECT_EQ(c.of, (std::vector<std::uint8_t>{0, 1, 0, 1, 1, 2, 2}));
  EXPECT_EQ(c.largest, (std::vector<double>{1.0, 0.5, 0.125}));
  EXPECT_EQ(c.members, (std::vector<std::size_t>{2, 3, 2}));
}

TEST(SizeClasses, SizesWithinAFactorTwoAreOneClass) {
  const SizeClasses c = size_classes({0.7, 1.0, 0.8, 0.500001, 1.0});
  ASSERT_EQ(c.count(), 1u);
  EXPECT_EQ(c.largest[0], 1.0);
  EXPECT_EQ(c.members[0], 5u);
}

TEST(SizeClasses, TheLastClassTakesTheSmallestAndZero) {
  const SizeClasses c = size_classes({64.0, 1.0, 0.0, 1e-9}, 4);
  ASSERT_EQ(c.count(), 2u);  // (32, 64] and everything up to 8
  EXPECT_EQ(c.of, (std::vector<std::uint8_t>{0, 1, 1, 1}));
  EXPECT_EQ(c.largest, (std::vector<double>{64.0, 1.0}));
  // All zero, or no particle: one class.
  EXPECT_EQ(size_classes({0.0, 0.0}).count(), 1u);
  EXPECT_EQ(size_classes({}).count(), 1u);
  EXPECT_EQ(size_classes({}).members[0], 0u);
}

}  // namespace
}  // namespace kairos
