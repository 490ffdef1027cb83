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

TEST(MosdLearnScans, OursFindsFortyOneObjectsWithOneFalseObstacle) {
  const SceneScore& s = Score().ours;
  // Target of issue 18: recall >= 95 % (44 of 46). Measured: 41 of 46
  // (89.1 %), a shortfall stated in docs/perception-clouds.md.
  EXPECT_GE(s.found, 41);
  // Target: at most 0.2 false obstacles per scene (2 in 14). Measured: 1.
  EXPECT_LE(s.false_obstacles, 1);
  // Target: >= 98 % of the table points labelled table. Measured: 99.76 %.
  EXPECT_GE(static_cast<double>(s.table_labelled) / s.table_points, 0.995);
}

TEST(MosdLearnScans, TextbookPipelineFindsSeventyTwoPercent) {
  // The anchor of issue 18 (measured there: 72 %); ours must beat it.
  const SceneScore& s = Score().textbook;
  EXPECT_EQ(s.found, 33);
  EXPECT_GT(Score().ours.found, s.found);
}

TEST(PersonScan, OnePersonSizedCluster) {
  const Cloud cloud = LoadPcd(kClouds + "/person.pcd");
  ObstaclePipeline pipeline(CloudParams{});
  const Result r = pipeline.Process(cloud);
  // The person is everything nearer than 1.2 m in this scan (the room's
  // walls are farther).
  long near = 0;
  for (const auto& p : cloud.points) near += p.allFinite() && p.z() < 1.2f;
  ASSERT_GT(near, 40000);
  ASSERT_FALSE(r.obstacles.empty());
  const Obstacle& person = r.obstacles[0];
  long held = 0;
  for (const int i : person.indices) held += cloud.points[i].z() < 1.2f;
  // Measured: 44184 of 46700 (94.6 %); the concave-crease cue cuts a part
  // in front of the body (2513 points, a 14 x 8 x 10 cm box) off as a
  // second, small obstacle.
  EXPECT_GE(held, 0.94 * near);
  EXPECT_GE(held, 0.95 * static_cast<double>(person.indices.size()));
  // Person-sized: the upper body in view, 0.3-2 m across its largest side.
  const float largest = 2.0f * person.half_extents.maxCoeff();
  EXPECT_GT(largest, 0.3f);
  EXPECT_LT(largest, 2.0f);
  // Nothing else of that size.
  for (std::size_t k = 1; k < r.obstacles.size(); ++k)
    EXPECT_LT(r.obstacles[k].indices.size(), person.indices.size() / 10) << k;
}

}  // namespace
}  // namespace iplan::cloud
