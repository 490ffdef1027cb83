#include <gtest/gtest.h>

#include "iplan/cell/people.h"

namespace iplan::cell {
namespace {

constexpr int64_t kSecond = 1'000'000'000;

TEST(PerBody, KeepsTheNewestValuePerBodyAndRefusesOutOfOrder) {
  PerBody<int> people;
  EXPECT_FALSE(people.Update(1, 10 * kSecond, 100));
  EXPECT_FALSE(people.Update(2, 11 * kSecond, 200));  // a second body does not replace the first
  ASSERT_EQ(people.size(), 2);
  EXPECT_EQ(people.Find(1)->value, 100);
  EXPECT_EQ(people.Find(2)->value, 200);
  // Older than body 1's newest: refused, value kept; newer than body 2's does not matter.
  const auto late = people.Update(1, 9 * kSecond, 101);
  ASSERT_TRUE(late);
  EXPECT_NE(late->find("out of order"), std::string::npos);
  EXPECT_TRUE(people.Update(1, 10 * kSecond, 102));  // equal stamp: refused too
  EXPECT_EQ(people.Find(1)->value, 100);
  EXPECT_EQ(people.Find(1)->stamp_ns, 10 * kSecond);
  EXPECT_FALSE(people.Update(1, 12 * kSecond, 103));
  EXPECT_EQ(people.Find(1)->value, 103);
  EXPECT_EQ(people.NewestStamp(), 12 * kSecond);
}

TEST(PerBody, ExpiresStaleBodiesOnly) {
  PerBody<int> people;
  people.Update(1, 10 * kSecond, 1);
  people.Update(2, 10 * kSecond + kSecond / 2, 2);
  people.Update(3, 11 * kSecond, 3);
  EXPECT_EQ(people.CountFresh(11 * kSecond + kSecond / 2, kSecond / 2), 1);  // body 3 only (0.5 s old)
  EXPECT_EQ(people.Expire(11 * kSecond + kSecond / 4, kSecond), 1);          // body 1: 1.25 s old
  EXPECT_EQ(people.Find(1), nullptr);
  ASSERT_NE(people.Find(2), nullptr);
  EXPECT_EQ(people.size(), 2);
  EXPECT_EQ(people.Expire(20 * kSecond, kSecond), 2);
  EXPECT_TRUE(people.empty());
  EXPECT_EQ(people.NewestStamp(), 0);
  // A dropped body comes back as new, whatever its old stamp was.
  EXPECT_FALSE(people.Update(1, 5 * kSecond, 7));
  EXPECT_EQ(people.Find(1)->value, 7);
}

TEST(PerBody, RefusesBodiesBeyondTheLimitWithoutEvicting) {
  PerBody<int> people(2);
  EXPECT_FALSE(people.Update(1, kSecond, 1));
  EXPECT_FALSE(people.Update(2, kSecond, 2));
  const auto third = people.Update(3, 2 * kSecond, 3);
  ASSERT_TRUE(third);
  EXPECT_EQ(*third, "already tracking 2 bodies (max 2); body 3 ignored");
  EXPECT_EQ(people.Find(3), nullptr);
  EXPECT_FALSE(people.Update(2, 2 * kSecond, 4));  // a known body still updates
  people.Expire(3 * kSecond, kSecond / 2);          // both gone
  EXPECT_FALSE(people.Update(3, 3 * kSecond, 3));
}

TEST(PerBody, TouchAppendsToTheBodysValue) {
  PerBody<std::vector<int>> history;
  std::string why;
  history.Touch(4, 1, &why)->push_back(1);
  history.Touch(4, 2, &why)->push_back(2);
  EXPECT_EQ(history.Touch(4, 2, &why), nullptr);
  EXPECT_EQ(history.Find(4)->value, (std::vector<int>{1, 2}));
}

TEST(UnionBound, IsTheSumOfThePersonsBoundsCappedAtOne) {
  EXPECT_DOUBLE_EQ(UnionBound({}), 0.0);
  EXPECT_DOUBLE_EQ(UnionBound({0.012}), 0.012);          // one person: that person's bound
  EXPECT_DOUBLE_EQ(UnionBound({0.012, 0.03}), 0.042);    // two: the sum
  EXPECT_DOUBLE_EQ(UnionBound({0.6, 0.7}), 1.0);         // capped
  EXPECT_DOUBLE_EQ(UnionBound({0.25, 0.25, 0.25, 0.25}), 1.0);
  EXPECT_DOUBLE_EQ(UnionBound({0.1, 0.0, 0.2, 0.05}), 0.35);
}

}  // namespace
}  // namespace iplan::cell
