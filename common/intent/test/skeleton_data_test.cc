#include "iplan/intent/skeleton_data.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "iplan/intent/features.h"

namespace iplan::intent {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const char* kHeader = "sequence,subject,action,frame,time,a.x,a.y,a.z,b.x,b.y,b.z\n";

TEST(SkeletonDataTest, LoadsSequencesInFileOrder) {
  const std::string path = WriteTemp(
      "ok.csv", std::string(kHeader) +
                    "s1,p1,wave,0,0.0,0,0,0,1,1,1\n"
                    "s1,p1,wave,1,0.1,1,0,0,2,1,1\n"
                    "s2,p2,clap,0,0.0,5,5,5,6,6,6\n");
  const SkeletonDataset d = LoadSkeletonCsv(path);
  ASSERT_EQ(d.joint_names, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(d.sequences.size(), 2u);
  EXPECT_EQ(d.sequences[0].id, "s1");
  EXPECT_EQ(d.sequences[0].action, "wave");
  EXPECT_EQ(d.sequences[0].positions.rows(), 2);
  EXPECT_DOUBLE_EQ(d.sequences[0].positions(1, 0), 1.0);
  EXPECT_DOUBLE_EQ(d.sequences[0].positions(1, 3), 2.0);
  EXPECT_DOUBLE_EQ(d.sequences[1].time(0), 0.0);
  EXPECT_EQ(SelectSubjects(d, {"p2"}).sequences.size(), 1u);
}

void ExpectLoadError(const std::string& body, const std::string& fragment) {
  const std::string path = WriteTemp("bad.csv", body);
  try {
    LoadSkeletonCsv(path);
    FAIL() << "no exception for: " << body;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
        << "message: " << e.what() << "\nexpected to contain: " << fragment;
  }
}

TEST(SkeletonDataTest, MalformedRowsNameFileAndLine) {
  ExpectLoadError(std::string(kHeader) + "s1,p1,wave,0,0.0,0,0,0,1,1\n", "bad.csv:2: row has 10 fields");
  ExpectLoadError(std::string(kHeader) + "s1,p1,wave,0,0.0,0,0,0,1,1,1\ns1,p1,wave,1,0.1,0,x,0,1,1,1\n",
                  "bad.csv:3: column 'a.y': 'x' is not a finite number");
  ExpectLoadError(std::string(kHeader) + "s1,p1,wave,0,0.0,0,0,0,1,1,1\ns1,p1,wave,1,0.0,0,0,0,1,1,1\n",
                  "bad.csv:3: time 0.0 does not increase");
  ExpectLoadError(std::string(kHeader) +
                      "s1,p1,wave,0,0.0,0,0,0,1,1,1\ns2,p1,wave,0,0.0,0,0,0,1,1,1\n"
                      "s1,p1,wave,1,0.1,0,0,0,1,1,1\n",
                  "bad.csv:4: rows of sequence 's1' are not contiguous");
  ExpectLoadError("sequence,subject,action,frame,time,a.x,a.y,b.z\n", "bad.csv:1: column 'b.z' should be 'a.z'");
  ExpectLoadError(std::string(kHeader) + "s1,p1,wave,0,nan,0,0,0,1,1,1\n", "'nan' is not a finite number");
}

TEST(SkeletonDataTest, UnknownSubjectAndJointAreNamed) {
  const std::string path = WriteTemp("ok2.csv", std::string(kHeader) + "s1,p1,wave,0,0.0,0,0,0,1,1,1\n");
  const SkeletonDataset d = LoadSkeletonCsv(path);
  EXPECT_THROW(
      {
        try {
          SelectSubjects(d, {"p7"});
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("subject 'p7'"), std::string::npos);
          throw;
        }
      },
      std::invalid_argument);
  EXPECT_THROW(JointIndices(d.joint_names, {"hand"}), std::invalid_argument);
}

TEST(SkeletonDataTest, ResamplesLinearlyAndSplitsLongGaps) {
  SkeletonSequence s;
  s.id = "x";
  s.time.resize(4);
  s.time << 0.0, 0.1, 0.3, 1.5;  // gap of 0.2 s bridged, gap of 1.2 s splits
  s.positions.resize(4, 3);
  s.positions << 0, 0, 1, 1, 0, 1, 3, 0, 1, 9, 9, 9;
  const std::vector<Track> tracks = ResampleSequence(s, {0}, 20.0, 0.5);
  ASSERT_EQ(tracks.size(), 2u);
  // 0 .. 0.3 s at 20 Hz: 7 samples, x = 10 t.
  ASSERT_EQ(tracks[0].positions.rows(), 7);
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(tracks[0].positions(i, 0), 10.0 * i / 20.0, 1e-12);
  EXPECT_EQ(tracks[1].positions.rows(), 1);
  EXPECT_EQ(tracks[1].sequence_id, "x#1");
  EXPECT_THROW(ResampleSequence(s, {0}, 0.0, 0.5), std::invalid_argument);
}

TEST(FeaturesTest, DefaultJointSetsPerDataset) {
  const JointConfig flo = DefaultJointConfig({"head", "neck", "torso", "shoulder_l", "elbow_l", "wrist_l",
                                              "shoulder_r", "elbow_r", "wrist_r", "hip_l"});
  EXPECT_EQ(flo.joints.size(), 9u);
  EXPECT_EQ(flo.torso, std::vector<std::string>{"torso"});
  EXPECT_EQ(flo.hands, (std::vector<std::string>{"wrist_l", "wrist_r"}));
  const JointConfig asm_ = DefaultJointConfig({"wrist_l", "wrist_r", "elbow_l", "elbow_r", "shoulder_l", "shoulder_r"});
  EXPECT_EQ(asm_.joints.size(), 6u);
  EXPECT_EQ(asm_.torso, (std::vector<std::string>{"shoulder_l", "shoulder_r"}));
  // No upper body by name: every joint of the data.
  EXPECT_EQ(DefaultJointConfig({"knee_l"}).joints, std::vector<std::string>{"knee_l"});
  EXPECT_THROW(DefaultJointConfig({}), std::invalid_argument);
}

TEST(FeaturesTest, FeaturesRelativeToTorsoAndObjects) {
  JointConfig c;
  c.joints = {"shoulder_l", "shoulder_r", "hand"};
  c.torso = {"shoulder_l", "shoulder_r"};
  c.hands = {"hand"};
  c.objects = {Eigen::Vector3d(1.0, 0.0, 0.0)};
  const FeatureLayout layout(c);
  Eigen::MatrixXd w(2, 9);
  w.row(0) << -0.2, 0, 0, 0.2, 0, 0, 0, 0.5, 0;
  w.row(1) = w.row(0);
  w.row(1).array() += 0.1;  // everything moves by (0.1, 0.1, 0.1)
  const Eigen::MatrixXd f = layout.FrameFeatures(w);
  ASSERT_EQ(f.cols(), 9 + 3 + 1);
  EXPECT_NEAR(f(1, 6), 0.0, 1e-12);   // hand x relative to torso
  EXPECT_NEAR(f(1, 7), 0.5, 1e-12);   // hand y relative to torso
  EXPECT_NEAR(f(0, 9), -0.1, 1e-12);  // torso of row 0 relative to newest torso
  EXPECT_NEAR(f(1, 12), (Eigen::Vector3d(0.1, 0.6, 0.1) - c.objects[0]).norm(), 1e-12);
  const Eigen::VectorXd x = layout.ForecastInput(w, 10.0, 1);
  EXPECT_NEAR(x(9 + 0), 0.0, 1e-12);  // joint velocity relative to torso
  EXPECT_NEAR(x(18), 1.0, 1e-12);     // torso velocity 0.1 m per 0.1 s
  JointConfig bad = c;
  bad.torso = {"pelvis"};
  EXPECT_NE(bad.Validate().find("torso joint 'pelvis'"), std::string::npos);
}

// Throws std::invalid_argument whose message contains `fragment`.
template <typename F>
void ExpectInvalid(const F& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "expected std::invalid_argument with: " << fragment;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "message: " << e.what();
  }
}

TEST(FeaturesTest, SelectedJointsAreHonouredBeforeAnyDefault) {
  // A tracker that gives one wrist only: no default skeleton exists, so the
  // default must not be computed for the parts that are named.
  const std::vector<std::string> wrist = {"wrist_r"};
  // With nothing named, a one-joint tracker's data gives that joint, the
  // joint itself as the torso reference and as the hand.
  const JointConfig tracked = DefaultJointConfig(wrist);
  EXPECT_EQ(tracked.joints, wrist);
  EXPECT_EQ(tracked.torso, wrist);
  EXPECT_EQ(tracked.hands, wrist);
  // Names of a tracker's own: every joint, the torso their mean.
  const std::vector<std::string> custom = {"nose", "left_index", "right_index"};
  EXPECT_EQ(DefaultJointConfig(custom).joints, custom);
  EXPECT_EQ(DefaultJointConfig(custom).torso, custom);
  EXPECT_TRUE(DefaultJointConfig(custom).hands.empty());
  ExpectInvalid([&] { DefaultJointConfig({}); }, "the data has no joints");
  JointSelection one;
  one.joints = wrist;
  one.torso = wrist;
  one.hands = std::vector<std::string>{};
  const JointConfig self = ResolveJointConfig(wrist, one);
  EXPECT_EQ(self.joints, wrist);
  EXPECT_EQ(self.torso, wrist);
  EXPECT_TRUE(self.hands.empty());
  one.torso = std::vector<std::string>{};  // none
  EXPECT_TRUE(ResolveJointConfig(wrist, one).torso.empty());
  // Hands default among the chosen joints; the torso has no default there.
  one.hands.reset();
  EXPECT_EQ(ResolveJointConfig(wrist, one).hands, wrist);
  one.torso.reset();
  EXPECT_EQ(ResolveJointConfig(wrist, one).torso, wrist);  // no torso by name: the joint itself
  // Names are the data's own, e.g. a 33-joint body tracker's.
  JointSelection own;
  own.joints = std::vector<std::string>{"left_index", "right_index", "nose"};
  own.torso = std::vector<std::string>{"nose"};
  const JointConfig mp = ResolveJointConfig({"nose", "left_index", "right_index", "left_heel"}, own);
  EXPECT_EQ(mp.joints.size(), 3u);
  EXPECT_TRUE(mp.hands.empty());
  // Default torso and hands among a chosen subset of a full skeleton.
  JointSelection arms;
  arms.joints = std::vector<std::string>{"shoulder_l", "shoulder_r", "wrist_r"};
  const JointConfig a = ResolveJointConfig({"head", "torso", "shoulder_l", "shoulder_r", "wrist_r"}, arms);
  EXPECT_EQ(a.torso, (std::vector<std::string>{"shoulder_l", "shoulder_r"}));  // not the data's torso
  EXPECT_EQ(a.hands, wrist);
}

TEST(FeaturesTest, MismatchedJointSetsAreRefusedNamingTheJoint) {
  JointSelection s;
  s.joints = std::vector<std::string>{"wrist_r", "wrist_l"};
  ExpectInvalid([&] { ResolveJointConfig({"wrist_r", "elbow_r"}, s); },
                "joint 'wrist_l' is not in the data (data joints: [wrist_r,elbow_r])");
  s.joints = std::vector<std::string>{"wrist_r"};
  s.torso = std::vector<std::string>{"elbow_r"};
  ExpectInvalid([&] { ResolveJointConfig({"wrist_r", "elbow_r"}, s); },
                "torso joint 'elbow_r' is not a model joint (joints: [wrist_r])");
  s.torso = std::vector<std::string>{};
  s.hands = std::vector<std::string>{"hand_r"};
  ExpectInvalid([&] { ResolveJointConfig({"wrist_r", "elbow_r"}, s); }, "hand joint 'hand_r' is not a model joint");
}

TEST(FeaturesTest, OneJointFeaturesWithTheJointOrNoTorsoAsReference) {
  // One wrist moving by (0.1, 0.2, 0) per frame at 10 Hz.
  Eigen::MatrixXd w(3, 3);
  w << 1.0, 0.0, 2.0, 1.1, 0.2, 2.0, 1.2, 0.4, 2.0;
  JointConfig self;
  self.joints = {"wrist_r"};
  self.torso = {"wrist_r"};
  const FeatureLayout own(self);
  ASSERT_EQ(own.frame_feature_size(), 6);
  ASSERT_EQ(own.forecast_input_size(), 12);
  const Eigen::MatrixXd f = own.FrameFeatures(w);
  EXPECT_EQ(f.leftCols(3).norm(), 0.0);                      // the joint relative to itself
  EXPECT_NEAR(f(0, 3), -0.2, 1e-12);                         // its motion relative to the newest frame
  EXPECT_NEAR(f(0, 4), -0.4, 1e-12);
  const Eigen::VectorXd x = own.ForecastInput(w, 10.0, 1);
  EXPECT_EQ(x.head(6).norm(), 0.0);                          // pose and velocity relative to itself
  EXPECT_NEAR((x.segment<3>(6) - Eigen::Vector3d(1.0, 2.0, 0.0)).norm(), 0.0, 1e-12);  // its velocity, m/s
  EXPECT_NEAR((x.segment<3>(9) - Eigen::Vector3d(0.2, 0.4, 0.0)).norm(), 0.0, 1e-12);  // displacement, m

  JointConfig none = self;
  none.torso.clear();
  ASSERT_EQ(none.Validate(), "");
  const FeatureLayout abs(none);
  EXPECT_EQ(abs.Torso(w.row(2)), Eigen::Vector3d::Zero());
  const Eigen::MatrixXd g = abs.FrameFeatures(w);
  EXPECT_EQ(g.leftCols(3), w);                               // positions in W
  EXPECT_EQ(g.rightCols(3).norm(), 0.0);                     // no torso motion
  const Eigen::VectorXd y = abs.ForecastInput(w, 10.0, 1);
  EXPECT_NEAR((y.head(3) - w.row(2).transpose()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((y.segment<3>(3) - Eigen::Vector3d(1.0, 2.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(y.tail(6).norm(), 0.0);
}

}  // namespace
}  // namespace iplan::intent

namespace iplan::intent {
namespace {

TEST(SkeletonDataTest, UndetectedJointsAreDroppedFramesNotErrors) {
  const std::string path = WriteTemp(
      "missing.csv", std::string(kHeader) +
                         "s1,p1,wave,0,0.0,0,0,1,1,1,1\n"
                         "s1,p1,wave,1,0.1,nan,nan,nan,1,1,1\n"
                         "s1,p1,wave,2,0.2,0,0,0,1,1,1\n"  // (0,0,0): not detected
                         "s1,p1,wave,3,0.3,3,0,1,1,1,1\n");
  const SkeletonDataset d = LoadSkeletonCsv(path);
  EXPECT_TRUE(std::isnan(d.sequences[0].positions(1, 0)));
  // Joint a: frames 1 and 2 are missing, 0 and 3 are interpolated across.
  const std::vector<Track> a = ResampleSequence(d.sequences[0], {0}, 10.0, 0.5);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(a[0].positions.rows(), 4);
  EXPECT_NEAR(a[0].positions(1, 0), 1.0, 1e-12);
  EXPECT_NEAR(a[0].positions(2, 0), 2.0, 1e-12);
  // Joint b alone is complete.
  EXPECT_EQ(ResampleSequence(d.sequences[0], {1}, 10.0, 0.5)[0].positions.rows(), 4);
  // With a short max_gap the missing frames split the track.
  EXPECT_EQ(ResampleSequence(d.sequences[0], {0, 1}, 10.0, 0.15).size(), 2u);
}

}  // namespace
}  // namespace iplan::intent
