#include "iplan/collision/human_model.h"

#include <cmath>
#include <fstream>
#include <random>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include "iplan/core/params.h"

namespace iplan::collision {
namespace {

Eigen::Matrix3d RandomSpd(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = 0.05 * n01(*rng);
  return A * A.transpose() + 1e-4 * Eigen::Matrix3d::Identity();
}

TEST(HumanModelTest, DefaultUpperBodyHasSixteenSpheres) {
  const HumanBodyModel body(HumanBodyParams::DefaultUpperBody());
  EXPECT_EQ(body.num_joints(), 9);
  EXPECT_EQ(body.num_spheres(), 16);
  for (const auto& s : body.spheres()) {
    EXPECT_GE(s.radius, 0.05);
    EXPECT_LE(s.radius, 0.20);
  }
  const HumanPrediction p = body.MakePrediction(10, 15);
  EXPECT_EQ(p.num_spheres(), 16);
  EXPECT_EQ(p.segment(15), 7);
}

// The sphere centre's Gaussian matches the statistics of
// (1 - u) z_a + u z_b with independent Gaussian joints.
TEST(HumanModelTest, SphereGaussianMatchesSampledStatistics) {
  const HumanBodyModel body(HumanBodyParams::DefaultUpperBody());
  std::mt19937_64 rng(41);
  std::normal_distribution<double> n01;
  Eigen::Matrix3Xd means(3, 9);
  std::vector<Eigen::Matrix3d> covs(9), chols(9);
  for (int j = 0; j < 9; ++j) {
    means.col(j) = Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    covs[j] = RandomSpd(&rng);
    chols[j] = covs[j].llt().matrixL();
  }
  constexpr int kSamples = 100000;
  for (int s : {0, 5, 8, 9}) {
    Eigen::Vector3d mean;
    Eigen::Matrix3d cov;
    body.CalcSphereGaussian(s, means, covs, &mean, &cov);
    const auto& def = body.spheres()[s];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum2 = Eigen::Matrix3d::Zero();
    for (int i = 0; i < kSamples; ++i) {
      const Eigen::Vector3d za = means.col(def.joint_a) + chols[def.joint_a] *
                                 Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      const Eigen::Vector3d zb = means.col(def.joint_b) + chols[def.joint_b] *
                                 Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      const Eigen::Vector3d c = (1 - def.u) * za + def.u * zb;
      sum += c;
      sum2 += c * c.transpose();
    }
    const Eigen::Vector3d m = sum / kSamples;
    const Eigen::Matrix3d S = sum2 / kSamples - m * m.transpose();
    // Standard error of the mean ~ sqrt(var / n); 6 SE tolerance.
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(m[i], mean[i], 6 * std::sqrt(cov(i, i) / kSamples)) << s;
      for (int j = 0; j < 3; ++j) {
        EXPECT_NEAR(S(i, j), cov(i, j),
                    6 * std::sqrt((cov(i, i) * cov(j, j) + cov(i, j) * cov(i, j)) / kSamples))
            << s;
      }
    }
  }
}

TEST(HumanModelTest, FillPredictionSetsEverySphere) {
  const HumanBodyModel body(HumanBodyParams::DefaultUpperBody());
  HumanPrediction p = body.MakePrediction(2, 3);
  std::mt19937_64 rng(43);
  Eigen::Matrix3Xd means = Eigen::Matrix3Xd::Random(3, 9);
  std::vector<Eigen::Matrix3d> covs(9);
  for (auto& c : covs) c = RandomSpd(&rng);
  ASSERT_TRUE(body.FillPrediction(means, covs, 1, 2, &p));
  for (int s = 0; s < 16; ++s) {
    Eigen::Vector3d mean;
    Eigen::Matrix3d cov;
    body.CalcSphereGaussian(s, means, covs, &mean, &cov);
    EXPECT_LE((p.sphere(1, 2, s).mean - mean).norm(), 1e-15);
    EXPECT_LE((p.sphere(1, 2, s).inverse * cov - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  }
  covs[0] = -Eigen::Matrix3d::Identity();
  covs[1] = -Eigen::Matrix3d::Identity();  // head segment: both joints bad
  EXPECT_FALSE(body.FillPrediction(means, covs, 0, 0, &p));
}

TEST(HumanModelTest, InvalidParamsAreRejectedWithReason) {
  HumanBodyParams p = HumanBodyParams::DefaultUpperBody();
  p.segments[3].joint_b = "knee";
  EXPECT_NE(p.Validate().find("unknown joint 'knee'"), std::string::npos) << p.Validate();
  EXPECT_THROW(HumanBodyModel{p}, std::invalid_argument);
  p = HumanBodyParams::DefaultUpperBody();
  p.segments[0].u = {0.5};
  EXPECT_NE(p.Validate().find("1 values of u for count = 2"), std::string::npos);
  p.segments[0].u = {0.5, 1.5};
  EXPECT_NE(p.Validate().find("u = 1.5"), std::string::npos);
  p = HumanBodyParams::DefaultUpperBody();
  p.segments[1].radius = -0.1;
  EXPECT_NE(p.Validate().find("radius = -0.1"), std::string::npos);
}

TEST(HumanModelTest, LoadsYamlStrictly) {
  const std::string good = ::testing::TempDir() + "body.yaml";
  std::ofstream(good) << "joints: [a, b, c]\n"
                         "segments:\n"
                         "  - {name: s1, joint_a: a, joint_b: b, count: 3, radius: 0.1}\n"
                         "  - {name: s2, joint_a: b, joint_b: c, count: 1, radius: 0.05, u: [1.0]}\n";
  const HumanBodyModel body(LoadHumanBodyParams(good));
  EXPECT_EQ(body.num_spheres(), 4);
  EXPECT_DOUBLE_EQ(body.spheres()[1].u, 0.5);
  EXPECT_DOUBLE_EQ(body.spheres()[3].u, 1.0);
  const std::string bad = ::testing::TempDir() + "body_bad.yaml";
  std::ofstream(bad) << "joints: [a, b]\n"
                        "segments:\n"
                        "  - {name: s1, joint_a: a, joint_b: b, count: 3, radus: 0.1}\n";
  try {
    LoadHumanBodyParams(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key 'segments[0].radus'"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos);
  }
}

TEST(HumanModelTest, AKeyWrittenTwiceIsAnError) {
  const std::string bad = ::testing::TempDir() + "body_twice.yaml";
  std::ofstream(bad) << "joints: [a, b]\n"
                        "segments:\n"
                        "  - {name: s1, joint_a: a, joint_b: b, count: 3, radius: 0.1}\n"
                        "joints: [a, b, c]\n";
  try {
    LoadHumanBodyParams(bad);
    ADD_FAILURE() << "a key written twice was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), bad + ": key 'joints': appears twice (lines 1 and 4)");
  }
}

}  // namespace
}  // namespace iplan::collision

namespace iplan::collision {
namespace {

TEST(HumanModelTest, ShippedConfigEqualsDefault) {
  const HumanBodyModel a(
      LoadHumanBodyParams(std::string(IPLAN_SOURCE_DIR) + "/config/humans/upper_body.yaml"));
  const HumanBodyModel b(HumanBodyParams::DefaultUpperBody());
  ASSERT_EQ(a.num_spheres(), b.num_spheres());
  EXPECT_EQ(a.params().joints, b.params().joints);
  for (int i = 0; i < a.num_spheres(); ++i) {
    EXPECT_EQ(a.spheres()[i].joint_a, b.spheres()[i].joint_a);
    EXPECT_EQ(a.spheres()[i].joint_b, b.spheres()[i].joint_b);
    EXPECT_DOUBLE_EQ(a.spheres()[i].u, b.spheres()[i].u);
    EXPECT_DOUBLE_EQ(a.spheres()[i].radius, b.spheres()[i].radius);
  }
}

TEST(HumanModelTest, TheDocumentedKeysAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(HumanBodyParams{})),
            "");
}

}  // namespace
}  // namespace iplan::collision
