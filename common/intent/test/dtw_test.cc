#include "iplan/intent/dtw.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

Eigen::MatrixXd Column(std::initializer_list<double> v) {
  Eigen::MatrixXd m(v.size(), 1);
  int i = 0;
  for (double x : v) m(i++, 0) = x;
  return m;
}

TEST(DtwTest, IdenticalSequencesHaveZeroDistance) {
  const Eigen::MatrixXd a = Column({0, 1, 2, 3});
  EXPECT_DOUBLE_EQ(DtwDistance(a, a, 1), 0.0);
}

TEST(DtwTest, HandComputedOneDimensional) {
  // a = (0, 1, 2), b = (0, 2). Cost |a_i - b_j|:
  //        b0  b1
  //   a0    0   2
  //   a1    1   1
  //   a2    2   0
  // Best path (0,0) (1,0) (2,1): 0 + 1 + 0 = 1; (0,0)(1,1)(2,1): 0 + 1 + 0 = 1.
  EXPECT_DOUBLE_EQ(DtwDistance(Column({0, 1, 2}), Column({0, 2}), -1), 1.0);
  // A shifted copy: warping absorbs the shift except at the ends.
  // a = (0, 0, 1, 2), b = (0, 1, 2, 2): path (0,0)(1,0)(2,1)(3,2)(3,3) costs 0.
  EXPECT_DOUBLE_EQ(DtwDistance(Column({0, 0, 1, 2}), Column({0, 1, 2, 2}), -1), 0.0);
}

TEST(DtwTest, BandRestrictsWarping) {
  // a = (0, 0, 0, 1), b = (1, 0, 0, 0), equal lengths.
  // Band 0 forces the diagonal: |0-1| + 0 + 0 + |1-0| = 2.
  const Eigen::MatrixXd a = Column({0, 0, 0, 1});
  const Eigen::MatrixXd b = Column({1, 0, 0, 0});
  EXPECT_DOUBLE_EQ(DtwDistance(a, b, 0), 2.0);
  // Unconstrained: (0,0)=1, then (1,1),(2,2),(2,3)... the ends still pay:
  // a0 must match b0 (cost 1) and a3 must match b3 (cost 1): also 2 here.
  EXPECT_DOUBLE_EQ(DtwDistance(a, b, -1), 2.0);
  // a = (0, 1, 0, 0), b = (0, 0, 1, 0): band 0 pays 2, band 1 aligns the peaks:
  // (0,0)(1,1)? no: (0,0)(0,1)(1,2)(2,3)(3,3) = 0 + 0 + 0 + 0 + 0.
  const Eigen::MatrixXd c = Column({0, 1, 0, 0});
  const Eigen::MatrixXd d = Column({0, 0, 1, 0});
  EXPECT_DOUBLE_EQ(DtwDistance(c, d, 0), 2.0);
  EXPECT_DOUBLE_EQ(DtwDistance(c, d, 1), 0.0);
}

TEST(DtwTest, EuclideanFrameCostInThreeDimensions) {
  Eigen::MatrixXd a(2, 3), b(2, 3);
  a << 0, 0, 0, 1, 2, 2;
  b << 0, 0, 0, 1, 2, 2;
  b(1, 2) = 2.0 + 3.0;  // second frame differs by (0, 0, 3)
  EXPECT_DOUBLE_EQ(DtwDistance(a, b, 0), 3.0);
  // With warping the second frame of b can only be matched by a's second
  // frame (both ends are pinned): still 3.
  EXPECT_DOUBLE_EQ(DtwDistance(a, b, -1), 3.0);
}

TEST(DtwTest, SymmetricAndMatchesColumnVariant) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  Eigen::MatrixXd a(9, 4), b(7, 4);
  for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = g(rng);
  for (Eigen::Index i = 0; i < b.size(); ++i) b.data()[i] = g(rng);
  const double ab = DtwDistance(a, b, 2);
  EXPECT_NEAR(ab, DtwDistance(b, a, 2), 1e-12);
  std::vector<double> ws;
  EXPECT_DOUBLE_EQ(ab, DtwDistanceColumns(a.transpose(), b.transpose(), 2, &ws));
  // A wider band can only lower (or keep) the distance.
  EXPECT_LE(DtwDistance(a, b, 5), ab + 1e-12);
}

TEST(DtwTest, KernelValues) {
  EXPECT_DOUBLE_EQ(DtwKernel(0.0, 0.3), 1.0);
  EXPECT_NEAR(DtwKernel(2.0, 1.0), std::exp(-2.0), 1e-15);
}

TEST(DtwTest, RejectsMismatchedFrames) {
  EXPECT_THROW(DtwDistance(Eigen::MatrixXd(2, 3), Eigen::MatrixXd(2, 2), 1),
               std::invalid_argument);
}

}  // namespace
}  // namespace iplan::intent
