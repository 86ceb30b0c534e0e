// RecentResults: exact matches only, the newest first, the oldest forgotten past the capacity.
#include "cleave/core/recent_results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace cleave {
namespace {

TEST(RecentResults, FindsOnlyEqualInputsAndForgetsTheOldestPastItsCapacity) {
  RecentResults<std::vector<double>, std::string> recent(2);
  const std::vector<double> a{1.0, 2.0}, b{3.0}, c{1.0, 2.0, 3.0};
  const auto found = [&](const std::vector<double>& input) {
    const std::string* result = recent.find(input);
    return result != nullptr ? *result : std::string("(none)");
  };
  EXPECT_EQ(recent.find(a), nullptr);
  recent.remember(a, "a");
  recent.remember(b, "b");
  EXPECT_EQ(found(a), "a");
  EXPECT_EQ(found(b), "b");
  EXPECT_EQ(recent.find(c), nullptr) << "a longer input with a as its start is another input";
  const std::vector<double> a_nudged{1.0, std::nextafter(2.0, 3.0)};
  EXPECT_EQ(recent.find(a_nudged), nullptr) << "one ulp off is another input";

  recent.remember(c, "c");  // past the capacity: a, the oldest, goes
  EXPECT_EQ(recent.size(), 2U);
  EXPECT_EQ(recent.find(a), nullptr);
  EXPECT_EQ(found(b), "b");
  EXPECT_EQ(found(c), "c");

  recent.remember(b, "b again");  // an equal input replaces its entry and becomes the newest
  EXPECT_EQ(recent.size(), 2U);
  EXPECT_EQ(found(b), "b again");
  recent.remember(a, "a");  // so c, now the oldest, goes
  EXPECT_EQ(recent.find(c), nullptr);
  EXPECT_EQ(found(b), "b again");
  recent.clear();
  EXPECT_EQ(recent.find(b), nullptr);
}

TEST(RecentResults, RenewMakesTheEntryFoundTheNewest) {
  RecentResults<std::vector<double>, std::string> recent(2);
  const std::vector<double> a{1.0}, b{2.0}, c{3.0};
  recent.remember(a, "a");
  recent.remember(b, "b");
  EXPECT_EQ(recent.renew(c), nullptr);
  const std::string* renewed = recent.renew(a);
  ASSERT_NE(renewed, nullptr);
  EXPECT_EQ(*renewed, "a");
  recent.remember(c, "c");  // b is the oldest now and goes, not a
  EXPECT_EQ(recent.size(), 2U);
  EXPECT_EQ(recent.find(b), nullptr);
  const std::string* kept = recent.find(a);
  ASSERT_NE(kept, nullptr);
  EXPECT_EQ(*kept, "a");
  EXPECT_NE(recent.find(c), nullptr);
}

}  // namespace
}  // namespace cleave
