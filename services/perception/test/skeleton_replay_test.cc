#include "../core/skeleton_replay.h"

#include <unistd.h>

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

namespace iplan::perception {
namespace {

// Two sequences of two subjects; joints a and b. Sequence q2 frame 1 has b
// undetected, frame 2 has nothing detected.
std::string WriteCsv() {
  const std::string path = ::testing::TempDir() + "/replay_test_" + std::to_string(getpid()) + ".csv";
  std::ofstream f(path);
  f << "sequence,subject,action,frame,time,a.x,a.y,a.z,b.x,b.y,b.z\n"
       "q1,s1,wave,0,0.0,1,0,0,0,1,0\n"
       "q1,s1,wave,1,0.1,1,0,1,0,1,1\n"
       "q2,s2,clap,0,0.0,2,0,0,0,2,0\n"
       "q2,s2,clap,1,0.05,2,0,1,nan,nan,nan\n"
       "q2,s2,clap,2,0.1,nan,nan,nan,0,0,0\n"
       "q2,s2,clap,3,0.2,2,0,3,0,2,3\n";
  return path;
}

std::vector<ReplayFrame> Drain(SkeletonReplay& r, double now) {
  std::vector<ReplayFrame> out;
  ReplayFrame f;
  while (r.Next(now, &f)) out.push_back(f);
  return out;
}

TEST(SkeletonReplay, PlaysFramesAtRecordedTimesInOrder) {
  SkeletonReplayParams p;
  p.file = WriteCsv();
  p.pause = 0.5;
  p.start_delay = 1.0;
  SkeletonReplay r(p);
  EXPECT_EQ(r.num_sequences(), 2);
  EXPECT_EQ(r.frames_per_pass(), 6);
  EXPECT_NEAR(r.pass_duration(), 0.1 + 0.5 + 0.2 + 0.5, 1e-12);
  EXPECT_TRUE(Drain(r, 0.99).empty());
  auto f = Drain(r, 1.05);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].sequence_id, "q1");
  EXPECT_EQ(f[0].body_id, 1u);
  EXPECT_DOUBLE_EQ(f[0].play_time, 1.0);
  f = Drain(r, 100.0);
  // q1 frame 1, q2 frames 0, 1, 3 (frame 2 has no detected joint).
  ASSERT_EQ(f.size(), 4u);
  EXPECT_NEAR(f[0].play_time, 1.1, 1e-12);
  EXPECT_EQ(f[1].sequence_id, "q2");
  EXPECT_EQ(f[1].body_id, 2u);
  EXPECT_EQ(f[1].action, "clap");
  EXPECT_NEAR(f[1].play_time, 1.6, 1e-12);
  ASSERT_EQ(f[2].joints.size(), 1u);  // b undetected
  EXPECT_EQ(f[2].joints[0].name, "a");
  EXPECT_NEAR(f[3].play_time, 1.8, 1e-12);
  EXPECT_TRUE(r.finished());
  EXPECT_TRUE(Drain(r, 1000.0).empty());
}

TEST(SkeletonReplay, SelectsScalesRenamesTransformsAndLoops) {
  SkeletonReplayParams p;
  p.file = WriteCsv();
  p.subjects = {"s1"};
  p.rate = 2.0;
  p.loop = true;
  p.joint_map = {{"b", "hand_r"}};
  p.X_WS = TransformFromTranslationYaw({1, 2, 3}, M_PI / 2);
  SkeletonReplay r(p);
  EXPECT_EQ(r.num_sequences(), 1);
  EXPECT_EQ(r.published_joint_names(), (std::vector<std::string>{"a", "hand_r"}));
  auto f = Drain(r, 0.05 + 0.5 + 0.05 + 0.01);  // 2 frames at 0, 0.05; next pass at 0.55, 0.6
  ASSERT_EQ(f.size(), 4u);
  EXPECT_NEAR(f[1].play_time, 0.05, 1e-12);
  EXPECT_EQ(f[0].body_id, 1u);
  EXPECT_EQ(f[2].body_id, 2u);  // a new pass is a new body
  ASSERT_EQ(f[1].joints.size(), 2u);
  EXPECT_EQ(f[1].joints[1].name, "hand_r");
  // b = (0, 1, 1) in S; yaw 90 deg maps S x -> W y, S y -> W -x.
  EXPECT_LT((f[1].joints[1].position_W - Eigen::Vector3d(1 - 1, 2 + 0, 3 + 1)).norm(), 1e-12);
  EXPECT_LT((f[1].joints[0].position_W - Eigen::Vector3d(1, 2 + 1, 3 + 1)).norm(), 1e-12);
  EXPECT_FALSE(r.finished());

  p.subjects = {};
  p.sequences = {"q2"};
  p.loop = false;
  SkeletonReplay only(p);
  EXPECT_EQ(only.num_sequences(), 1);
  EXPECT_EQ(Drain(only, 10.0).front().sequence_id, "q2");
}

TEST(SkeletonReplay, BadSelectionsAndParamsAreRefusedWithTheName) {
  SkeletonReplayParams p;
  p.file = WriteCsv();
  auto message = [](const SkeletonReplayParams& q) -> std::string {
    try {
      SkeletonReplay r(q);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  SkeletonReplayParams q = p;
  q.sequences = {"q9"};
  EXPECT_NE(message(q).find("sequence 'q9' is not in"), std::string::npos) << message(q);
  q = p;
  q.subjects = {"s7"};
  EXPECT_NE(message(q).find("s7"), std::string::npos) << message(q);
  q = p;
  q.joint_map = {{"wrist", "hand"}};
  EXPECT_NE(message(q).find("joint_map: joint 'wrist' is not in"), std::string::npos) << message(q);
  q = p;
  q.joint_map = {{"a", "b"}};
  EXPECT_NE(message(q).find("same name"), std::string::npos) << message(q);
  q = p;
  q.rate = 0;
  EXPECT_NE(message(q).find("rate must be > 0"), std::string::npos) << message(q);
  q = p;
  q.file = "/nonexistent/x.csv";
  EXPECT_NE(message(q).find("/nonexistent/x.csv"), std::string::npos) << message(q);
}

TEST(SkeletonReplay, MatrixTransformIsCheckedForRigidity) {
  Eigen::Isometry3d X;
  EXPECT_EQ(TransformFromMatrix({0, -1, 0, 1, 1, 0, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1}, &X), "");
  EXPECT_LT((X.matrix() - TransformFromTranslationYaw({1, 2, 3}, M_PI / 2).matrix()).norm(), 1e-12);
  EXPECT_NE(TransformFromMatrix({1, 0, 0}, &X).find("16 numbers"), std::string::npos);
  EXPECT_NE(TransformFromMatrix({2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, &X).find("rotation"),
            std::string::npos);
  EXPECT_NE(TransformFromMatrix({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1}, &X).find("last row"),
            std::string::npos);
  // A reflection is orthonormal but not a rotation.
  EXPECT_NE(TransformFromMatrix({-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, &X).find("rotation"),
            std::string::npos);
}

}  // namespace
}  // namespace iplan::perception
