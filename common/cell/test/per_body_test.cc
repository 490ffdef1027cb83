#include <gtest/gtest.h>

#include "iplan/cell/people.h"
#include "iplan/cell/timed_prediction.h"

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

// One action, two steps, every joint of the default upper body at the
// origin with 1 cm standard deviation.
collision::JointMixture StillPerson(const collision::HumanBodyModel& body, int64_t t0_ns) {
  collision::JointMixture m;
  m.t0_ns = t0_ns;
  m.time_step = 0.1;
  m.num_steps = 2;
  m.joint_names = body.params().joints;
  m.actions = {"still"};
  m.probabilities = {1.0};
  m.means = {std::vector<Eigen::Vector3d>(2 * body.num_joints(), Eigen::Vector3d::Zero())};
  m.covariances = {std::vector<Eigen::Matrix3d>(2 * body.num_joints(), 1e-4 * Eigen::Matrix3d::Identity())};
  return m;
}

TEST(KeepNewestPrediction, BuildsExpiresAndRefusesLikeTheStore) {
  const collision::HumanBodyModel body(collision::HumanBodyParams::DefaultUpperBody());
  PerBody<TimedPrediction> store;
  EXPECT_FALSE(KeepNewestPrediction(body, 1, StillPerson(body, 10 * kSecond), 1.0, &store));
  ASSERT_NE(store.Find(1), nullptr);
  EXPECT_EQ(store.Find(1)->value.t0_ns(), 10 * kSecond);
  EXPECT_EQ(store.Find(1)->value.num_steps(), 2);
  // Out of order: refused with the store's reason, the newest kept.
  const auto late = KeepNewestPrediction(body, 1, StillPerson(body, 9 * kSecond), 1.0, &store);
  ASSERT_TRUE(late);
  EXPECT_EQ(late->rfind("prediction: ", 0), 0u) << *late;
  EXPECT_NE(late->find("out of order"), std::string::npos) << *late;
  EXPECT_EQ(store.Find(1)->value.t0_ns(), 10 * kSecond);
  // A mixture that cannot be built: refused before anything expires.
  collision::JointMixture bad = StillPerson(body, 30 * kSecond);
  bad.actions.clear();
  EXPECT_TRUE(KeepNewestPrediction(body, 2, bad, 1.0, &store));
  EXPECT_EQ(store.size(), 1);
  // Another person 1.5 s later: the first, older than 1 s, is dropped.
  EXPECT_FALSE(KeepNewestPrediction(body, 2, StillPerson(body, 11 * kSecond + kSecond / 2), 1.0, &store));
  EXPECT_EQ(store.Find(1), nullptr);
  ASSERT_NE(store.Find(2), nullptr);
  EXPECT_EQ(store.size(), 1);
}

}  // namespace
}  // namespace iplan::cell
