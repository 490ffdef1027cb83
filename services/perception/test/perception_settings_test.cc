// Section perception, declared once (perception_settings.h): the shipped
// file, the conversions to the cores' parameters, and refusals by key.
#include "services/perception/perception_settings.h"

#include <fstream>

#include <gtest/gtest.h>

#include "iplan/framework/service_file.h"

namespace iplan::perception {
namespace {

const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";

PerceptionSettings Read(const std::string& yaml, std::string* error = nullptr) {
  const std::string path = ::testing::TempDir() + "perception_settings.yaml";
  std::ofstream(path) << yaml;
  PerceptionSettings s;
  try {
    framework::ServiceFile(path).ReadSection("perception", &s).Finish();
  } catch (const core::ConfigError& e) {
    if (error) *error = e.what();
  }
  return s;
}

std::string Refusal(const std::string& yaml) {
  std::string error;
  Read(yaml, &error);
  return error;
}

TEST(PerceptionSettings, TheShippedFileGivesTheCellsPerson) {
  PerceptionSettings s;
  framework::ServiceFile(kConfig + "/perception.yaml").ReadSection("perception", &s).Finish();
  EXPECT_EQ(s.provider, "synthetic");
  EXPECT_EQ(s.rate_hz, 30);
  EXPECT_TRUE(s.publish_truth);
  EXPECT_EQ(s.synthetic.Start(), ScriptStart::kEpisodes);
  const SyntheticPersonParams p = s.synthetic.Person();
  EXPECT_FALSE(p.loop);
  EXPECT_TRUE(p.torso_W.isApprox(Eigen::Vector3d(1.30, 0.0, 0.25)));
  // The actions in the file's order, each converted.
  ASSERT_EQ(p.actions.size(), 3u);
  EXPECT_EQ(p.actions[0].name, "reach_parts");
  EXPECT_EQ(p.actions[0].kind, MotionKind::kReach);
  EXPECT_TRUE(p.actions[0].right_hand);
  EXPECT_TRUE(p.actions[0].target_W.isApprox(Eigen::Vector3d(0.89, 0.36, 0.17)));
  EXPECT_EQ(p.actions[0].period, 3.0);
  EXPECT_EQ(p.actions[1].name, "assemble");
  EXPECT_EQ(p.actions[1].kind, MotionKind::kWork);
  EXPECT_EQ(p.actions[1].amplitude, 0.04);
  EXPECT_EQ(p.actions[2].kind, MotionKind::kRest);
  ASSERT_EQ(p.script.size(), 3u);
  EXPECT_EQ(p.script[1].action, "assemble");
  EXPECT_EQ(p.script[2].duration, 1.0);
  EXPECT_TRUE(s.synthetic.MorePeople().empty());
  EXPECT_EQ(s.depth.provider, "none");
  EXPECT_EQ(s.depth.rate_hz, 10);
  EXPECT_EQ(s.depth.simulated.scenes, std::vector<std::string>{"scenes/cell.yaml"});
}

TEST(PerceptionSettings, FurtherPeopleTakeTheFirstPersonsKeysTheyDoNotGive) {
  const PerceptionSettings s =
      Read("perception:\n  synthetic:\n    seed: 4\n    torso: [1.2, 0, 0.3]\n"
           "    more_people: [{torso: [2.0, 0.5, 0.3]}, {facing_yaw: 1.0, seed: 40}]\n");
  const std::vector<SyntheticPersonParams> more = s.synthetic.MorePeople();
  ASSERT_EQ(more.size(), 2u);
  EXPECT_TRUE(more[0].torso_W.isApprox(Eigen::Vector3d(2.0, 0.5, 0.3)));
  EXPECT_EQ(more[0].seed, 5u);  // the first person's + the index
  EXPECT_TRUE(more[1].torso_W.isApprox(Eigen::Vector3d(1.2, 0, 0.3)));
  EXPECT_EQ(more[1].facing_yaw, 1.0);
  EXPECT_EQ(more[1].seed, 40u);
}

TEST(PerceptionSettings, NoFileMeansOneDefaultReach) {
  const PerceptionSettings s = Read("perception: {}\n");
  const SyntheticPersonParams p = s.synthetic.Person();
  ASSERT_EQ(p.actions.size(), 1u);
  EXPECT_EQ(p.actions[0].name, "reach");
  EXPECT_TRUE(p.actions[0].target_W.isApprox(SyntheticPersonParams{}.actions[0].target_W));
  EXPECT_TRUE(p.loop);
  EXPECT_EQ(p.Validate(), "");
}

TEST(PerceptionSettings, BadValuesAreRefusedNamingTheKey) {
  EXPECT_NE(Refusal("perception:\n  synthetic:\n    actions: {jump: {motion: hop, target: [1, 0, 0]}}\n"
                    "    script: [jump]\n    durations: [1]\n")
                .find("synthetic.actions.jump.motion must be reach, work or rest, got 'hop'"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  synthetic:\n    actions: {r: {motion: reach}}\n").find(
                "synthetic.actions.r.target is required for motion reach"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  synthetic:\n    actions: {r: {hand: right, target: [1, 0, 0]}}\n").find(
                "key 'perception.synthetic.actions.r.motion': is required but missing"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  synthetic:\n    script: [reach]\n").find(
                "synthetic.durations must have one duration (s) per script step (1), got 0"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  synthetic:\n    script: [walk]\n    durations: [1]\n").find(
                "script step 'walk' names no defined action"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  replay:\n    transform: {yaw: 1, matrix: [1]}\n").find(
                "replay.transform.matrix: give either matrix or translation/yaw, not both"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  depth:\n    provider: pcd\n").find(
                "depth.pcd.path is required with provider pcd"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  depth:\n    provider: pcd\n    transport: image\n    pcd: {path: scans}\n")
                .find("depth.transport image needs provider simulated: a PCD file carries no camera intrinsics"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  depth:\n    simulated:\n      intrinsics: {fx: 0}\n").find(
                "depth.simulated.intrinsics.fx must be > 0"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  depth:\n    simulated:\n      camera: {position: [0, 0, 1], look_at: [0, 0, 0]}\n")
                .find("depth.simulated.camera:"),
            std::string::npos);
  EXPECT_NE(Refusal("perception:\n  synthetic:\n    actions: {r: {motion: rest, colour: red}}\n").find(
                "unknown key 'perception.synthetic.actions.r.colour'"),
            std::string::npos);
  EXPECT_EQ(Refusal("perception:\n  synthetic:\n    actions: {r: {motion: rest}}\n"), "");
}

TEST(PerceptionSettings, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(PerceptionSettings{})),
            "");
}

}  // namespace
}  // namespace iplan::perception
