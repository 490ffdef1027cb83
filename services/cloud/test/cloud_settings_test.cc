// Section cloud read from its declaration (CloudSettings): the documented
// defaults, the cell's own file, bad values named with the file.
#include "services/cloud/core/cloud_settings.h"

#include <fstream>

#include <gtest/gtest.h>

#include "iplan/core/params.h"

namespace iplan::cloud_service {
namespace {

TEST(CloudSettings, TheDocumentedDefaultsAreTheDeclaredOnesAndValid) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(CloudSettings{})),
            "");
  EXPECT_EQ(CloudSettings{}.Validate(), "");
}

TEST(CloudSettings, TheCellsFileReadsCleanly) {
  core::ConfigSection file = core::ConfigSection::Load(std::string(IPLAN_SOURCE_DIR) + "/config/cloud.yaml");
  core::ConfigSection section = file.Section("cloud");
  std::string pipeline;
  section.ReadParamsFile("pipeline", "cloud_pipeline.yaml", &pipeline);
  CloudSettings s;
  core::ReadParams(section, &s);
  ASSERT_TRUE(file.Problems().empty()) << file.Problems().front();
  EXPECT_EQ(s.workspace_min, (std::array<double, 3>{-0.3, -0.6, -0.1}));
  EXPECT_EQ(s.tracking.static_frames, 10);
  const CloudStageParams p = s.StageParams();
  // The camera at its position, looking at its target (the optical z axis).
  EXPECT_LT((p.X_WS.translation() - Eigen::Vector3d(0.45, 1.3, 1.1)).norm(), 1e-12);
  const Eigen::Vector3d view = (Eigen::Vector3d(0.6, 0.0, 0.1) - Eigen::Vector3d(0.45, 1.3, 1.1)).normalized();
  EXPECT_LT((p.X_WS.linear().col(2) - view).norm(), 1e-12);
  EXPECT_EQ(p.workspace_max, Eigen::Vector3d(1.8, 0.8, 1.4));
}

TEST(CloudSettings, BadValuesAreNamedWithTheFile) {
  const std::string path = ::testing::TempDir() + "/cloud_bad.yaml";
  for (const auto& [yaml, expected] : std::vector<std::pair<std::string, std::string>>{
           {"cloud:\n  workspace_min: [0, 0]\n", "key 'cloud.workspace_min'"},
           {"cloud:\n  workspace_min: [3, 0, 0]\n", "workspace_min must be below workspace_max"},
           {"cloud:\n  camera: {position: [1, 1, 1], look_at: [1, 1, 1]}\n", "camera: "},
           {"cloud:\n  noise: {focal_px: 0}\n", "noise: "},
           {"cloud:\n  joint_state_timeout: 0\n", "joint_state_timeout must be > 0 s"},
           {"cloud:\n  tracking: {lost_frames: -1}\n", "tracking"},
       }) {
    { std::ofstream(path) << yaml; }
    core::ConfigSection file = core::ConfigSection::Load(path);
    CloudSettings s;
    core::ReadParams(file.Section("cloud"), &s);
    ASSERT_FALSE(file.Problems().empty()) << yaml;
    EXPECT_NE(file.Problems().front().find(path), std::string::npos) << file.Problems().front();
    EXPECT_NE(file.Problems().front().find(expected), std::string::npos) << yaml << ": " << file.Problems().front();
  }
}

}  // namespace
}  // namespace iplan::cloud_service
