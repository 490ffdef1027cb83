// Both pipelines on the shared real scans (../shared/data/pointclouds): the
// quality figures of docs/perception-clouds.md, asserted at the measured
// level (the targets are stated beside them; where ours falls short
// the docs say so).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "iplan/cloud/cloud.h"
#include "iplan/cloud/evaluate.h"
#include "iplan/cloud/pipeline.h"

namespace iplan::cloud {
namespace {

const std::string kClouds = std::string(IPLAN_SHARED_DIR) + "/data/pointclouds";

std::vector<std::string> LearnScenes() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(kClouds + "/mosd_learn"))
    if (e.path().extension() == ".pcd") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

struct Totals {
  SceneScore ours, textbook;
  int scenes = 0;
};

const Totals& Score() {
  static const Totals totals = [] {
    Totals t;
    ObstaclePipeline ours(CloudParams{});
    for (const auto& f : LearnScenes()) {
      const Cloud cloud = LoadPcd(f);
      EXPECT_EQ(cloud.label.size(), cloud.size()) << f;
      t.ours = Add(t.ours, ScoreScene(cloud.label, ours.Process(cloud).labels));
      t.textbook = Add(t.textbook, ScoreScene(cloud.label, TextbookPipeline(cloud, CloudParams{}).labels));
      ++t.scenes;
    }
    return t;
  }();
  return totals;
}

TEST(MosdLearnScans, AllFourteenScenesWithFortySixObjects) {
  EXPECT_EQ(Score().scenes, 14);
  EXPECT_EQ(Score().ours.objects, 46);
  EXPECT_EQ(Score().textbook.objects, 46);
}

TEST(MosdLearnScans, OursFindsFortyThreeObjectsWithNoFalseObstacle) {
  const SceneScore& s = Score().ours;
  // Target of issue 29: recall >= 95 % (44 of 46). Measured: 43 of 46
  // (93.5 %), a shortfall stated in docs/perception-clouds.md.
  EXPECT_GE(s.found, 43);
  // Target: at most 0.2 false obstacles per scene (2 in 14). Measured: 0.
  EXPECT_LE(s.false_obstacles, 0);
  // Target: >= 98 % of the table points labelled table. Measured: 99.76 %.
  EXPECT_GE(static_cast<double>(s.table_labelled) / s.table_points, 0.995);
}

TEST(MosdLearnScans, TextbookPipelineFindsSeventyTwoPercent) {
  // The anchor of issue 18 (measured there: 72 %); ours must beat it.
  const SceneScore& s = Score().textbook;
  EXPECT_EQ(s.found, 33);
  EXPECT_GT(Score().ours.found, s.found);
}

TEST(PersonScan, OnePersonSizedGroup) {
  const Cloud cloud = LoadPcd(kClouds + "/person.pcd");
  ObstaclePipeline pipeline(CloudParams{});
  const Result r = pipeline.Process(cloud);
  // The person is everything nearer than 1.2 m in this scan (the room's
  // walls are farther).
  long near = 0;
  for (const auto& p : cloud.points) near += p.allFinite() && p.z() < 1.2f;
  ASSERT_GT(near, 40000);
  ASSERT_FALSE(r.obstacles.empty());
  // The creases cut the body into parts (arms, torso: measured 5 parts);
  // they are one group, connected in depth.
  const int person = r.obstacles[0].group;
  long held = 0, size = 0;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const Obstacle& o : r.obstacles) {
    if (o.group != person) continue;
    size += static_cast<long>(o.indices.size());
    for (const int i : o.indices) {
      held += cloud.points[i].z() < 1.2f;
      lo = lo.cwiseMin(cloud.points[i]);
      hi = hi.cwiseMax(cloud.points[i]);
    }
  }
  // Measured: 46672 of the 46700 near points, all of the group near.
  EXPECT_GE(held, 0.99 * near);
  EXPECT_GE(held, 0.99 * size);
  // Person-sized: the upper body in view, 0.3-2 m across its largest side.
  const float largest = (hi - lo).maxCoeff();
  EXPECT_GT(largest, 0.3f);
  EXPECT_LT(largest, 2.0f);
  // Nothing else of that size.
  for (const Obstacle& o : r.obstacles) {
    if (o.group == person) continue;
    EXPECT_LT(static_cast<long>(o.indices.size()), size / 10) << o.id;
  }
}

}  // namespace
}  // namespace iplan::cloud
