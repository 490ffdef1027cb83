#include "iplan/intent/model_selection.h"

#include <limits>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

TEST(ModelSelectionTest, AGainSmallerThanTheFoldScatterIsNotTaken) {
  // Option 1 is 0.001 better on average, but the folds disagree by +-0.01.
  Eigen::MatrixXd e(2, 4);
  e << 1.000, 1.000, 1.000, 1.000,
       0.990, 1.010, 0.985, 1.011;
  EXPECT_EQ(SimplestWithinOneStandardError(e), 0);
}

TEST(ModelSelectionTest, AConsistentGainIsTaken) {
  // Option 2 is better in every fold by about 0.1 (scatter 0.005).
  Eigen::MatrixXd e(3, 4);
  e << 1.00, 1.10, 0.90, 1.00,
       0.99, 1.09, 0.89, 0.99,
       0.90, 0.99, 0.80, 0.91;
  EXPECT_EQ(SimplestWithinOneStandardError(e), 2);
}

TEST(ModelSelectionTest, TheSimplestOfSeveralWithinOneStandardErrorWins) {
  // Options 1 and 2 are both far better than 0; 2 is better than 1 by less
  // than the scatter of their difference, so 1 is taken.
  Eigen::MatrixXd e(3, 3);
  e << 2.0, 2.0, 2.0,
       1.0, 1.2, 0.8,
       0.95, 1.25, 0.7;
  EXPECT_EQ(SimplestWithinOneStandardError(e), 1);
}

TEST(ModelSelectionTest, OneFoldOrIncompleteFoldsFallBackToTheBest) {
  Eigen::MatrixXd one(2, 1);
  one << 1.0, 0.5;
  EXPECT_EQ(SimplestWithinOneStandardError(one), 1);
  // A fold some option was not scored on is left out: one usable fold remains.
  Eigen::MatrixXd gap(2, 2);
  gap << 1.0, std::numeric_limits<double>::quiet_NaN(),
         0.5, 0.4;
  EXPECT_EQ(SimplestWithinOneStandardError(gap), 1);
  EXPECT_EQ(SimplestWithinOneStandardError(Eigen::MatrixXd(2, 0)), 0);
}

}  // namespace
}  // namespace iplan::intent
