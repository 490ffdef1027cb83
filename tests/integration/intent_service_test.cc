// The intent service as a real process: a small model is trained here on
// Florence 3D (two subjects), iplan-perception replays recorded sequences of
// another subject (fastdds) into iplan-intent (cyclonedds), and this process
// checks that every skeleton gets a belief and a prediction with consistent
// stamps, sizes and valid Gaussians. Garbage skeletons are rejected and
// counted without output and without a crash; a model that does not match
// the configuration is refused at start (exit code 2).
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <set>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "iplan/dds/participant.h"
#include "iplan/framework/node.h"
#include "iplan/intent/intent_model.h"
#include "iplan/intent/model_io.h"
#include "iplan/intent/skeleton_data.h"
#include "iplan/msg/time.h"
#include "cell_harness.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

const std::string kCsv = std::string(IPLAN_SHARED_DIR) + "/data/florence3d.csv";
const std::string kSkeletonTopic = framework::topics::HumanSkeleton().name;
// Played sequences (subject s02, not in the training set).
const std::vector<std::string> kPlayed = {"florence_a01_s02_e01", "florence_a04_s02_e01", "florence_a06_s02_e01",
                                          "florence_a08_s02_e02", "florence_a09_s02_e02"};
const Eigen::Vector3d kSensorInWorld(0.5, -0.2, 0.1);  // replay transform: translation only, m

class IntentServiceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(::testing::TempDir() + "/iplan-intent-svc-" + std::to_string(getpid()));
    fs::create_directories(*dir_);
    // Florence names the hands wrist_*; the replay's joint_map publishes them
    // as hand_* (the names of the default skeleton), so train with those names.
    intent::SkeletonDataset all = intent::LoadSkeletonCsv(kCsv);
    for (auto& n : all.joint_names) {
      if (n == "wrist_l") n = "hand_l";
      if (n == "wrist_r") n = "hand_r";
    }
    played_ = new intent::SkeletonDataset(intent::SelectSubjects(all, {"s02"}));
    intent::IntentModelConfig c;
    c.joints = intent::DefaultJointConfig(all.joint_names);
    c.rate = 15.0;
    c.window = 8;
    c.horizon = 6;
    intent::TrainParams p;
    p.sigma_factors = {1.0};
    p.lambdas = {1e-3};
    p.pseudo_inputs = 8;
    p.gp_iterations = 20;
    p.max_forecast_windows = 80;
    model_ = new intent::IntentModel(intent::TrainIntentModel(intent::SelectSubjects(all, {"s01", "s03"}), c, p));
    intent::SaveIntentModel(*model_, *dir_ + "/florence.model");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete model_;
    delete played_;
    delete dir_;
  }

  static std::string Write(const std::string& name, const std::string& content) {
    const std::string path = *dir_ + "/" + name;
    std::ofstream(path) << content;
    return path;
  }
  // An intent configuration of the trained model (or `model`, relative to
  // the file's folder).
  static std::string IntentConfigText(const std::vector<std::string>& joints, double rate, const std::string& model = "") {
    std::string list;
    for (const auto& j : joints) list += (list.empty() ? "" : ", ") + j;
    return "node:\n  diagnostics_period: 0.2\nintent:\n  model: " + (model.empty() ? *dir_ + "/florence.model" : model) +
           "\n  joints: [" + list + "]\n  rate_hz: " + std::to_string(rate) + "\n  body_timeout: 1.0\n";
  }
  static std::string IntentConfig(const std::string& name, const std::vector<std::string>& joints, double rate,
                                  const std::string& model = "") {
    return Write(name, IntentConfigText(joints, rate, model));
  }

  // A perception configuration replaying kPlayed once, moved into W.
  static std::string ReplayConfigText() {
    std::string seqs;
    for (const auto& s : kPlayed) seqs += (seqs.empty() ? "" : ", ") + s;
    return "node:\n  diagnostics_period: 0.2\nperception:\n  provider: replay\n  frame_id: world\n  replay:\n"
           "    file: " + kCsv + "\n    sequences: [" + seqs + "]\n    loop: false\n    rate: 1.0\n    pause: 0.3\n"
           "    start_delay: 2.0\n    joint_map:\n      wrist_l: hand_l\n      wrist_r: hand_r\n"
           "    transform:\n      translation: [0.5, -0.2, 0.1]\n      yaw: 0\n";
  }

  static std::string* dir_;
  static intent::IntentModel* model_;
  static intent::SkeletonDataset* played_;
};
std::string* IntentServiceTest::dir_ = nullptr;
intent::IntentModel* IntentServiceTest::model_ = nullptr;
intent::SkeletonDataset* IntentServiceTest::played_ = nullptr;

// What the observer saw, by stamp (ns): skeletons by their stamp, beliefs
// and predictions by the stamp of the skeleton they come from.
struct Observed {
  std::map<int64_t, msg::HumanSkeleton> skeletons;
  std::map<int64_t, msg::ActionBelief> beliefs;
  std::map<int64_t, msg::HumanPrediction> predictions;
  int duplicate_outputs = 0;
  void Subscribe(framework::Node& node) {
    node.Subscribe(framework::topics::HumanSkeleton(),
                   std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                       [this](const msg::HumanSkeleton& s, const dds::SampleInfo&) {
                         skeletons[msg::ToNanoseconds(s.header.stamp)] = s;
                       }));
    node.Subscribe(framework::topics::ActionBelief(),
                   std::function<void(const msg::ActionBelief&, const dds::SampleInfo&)>(
                       [this](const msg::ActionBelief& b, const dds::SampleInfo&) {
                         // Outputs carry intent's own stamp, never older than the skeleton's.
                         EXPECT_GE(msg::ToNanoseconds(b.header.stamp), msg::ToNanoseconds(b.observation_stamp));
                         duplicate_outputs += beliefs.count(msg::ToNanoseconds(b.observation_stamp));
                         beliefs[msg::ToNanoseconds(b.observation_stamp)] = b;
                       }));
    node.Subscribe(framework::topics::HumanPrediction(),
                   std::function<void(const msg::HumanPrediction&, const dds::SampleInfo&)>(
                       [this](const msg::HumanPrediction& p, const dds::SampleInfo&) {
                         EXPECT_GE(msg::ToNanoseconds(p.header.stamp), msg::ToNanoseconds(p.observation_stamp));
                         duplicate_outputs += predictions.count(msg::ToNanoseconds(p.observation_stamp));
                         predictions[msg::ToNanoseconds(p.observation_stamp)] = p;
                       }));
  }
};

// The belief and prediction made from skeleton `s`: the model's actions, a
// distribution, SPD covariances, and step 0 near the skeleton. Adds the
// joints compared to *checked_steps.
void CheckOutputs(const intent::IntentModel& model, const std::vector<std::string>& joints, const msg::HumanSkeleton& s,
                  const msg::ActionBelief& belief, const msg::HumanPrediction& pred, int* checked_steps) {
  EXPECT_EQ(belief.body_id, s.body_id);
  EXPECT_EQ(pred.body_id, s.body_id);
  EXPECT_EQ(belief.header.frame_id, "world");
  ASSERT_EQ(belief.actions, model.actions);
  ASSERT_EQ(belief.probabilities.size(), model.actions.size());
  double sum = 0;
  for (double q : belief.probabilities) {
    EXPECT_GE(q, 0.0);
    EXPECT_LE(q, 1.0);
    sum += q;
  }
  EXPECT_NEAR(sum, 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(pred.time_step, 1.0 / 15.0);
  ASSERT_EQ(pred.num_steps, 6u);
  ASSERT_EQ(pred.joint_names, joints);
  ASSERT_EQ(pred.actions.size(), model.actions.size());
  // Probability-weighted mean of step 0 for each joint, to compare with the skeleton.
  std::vector<Eigen::Vector3d> step0(joints.size(), Eigen::Vector3d::Zero());
  for (std::size_t c = 0; c < pred.actions.size(); ++c) {
    const auto& a = pred.actions[c];
    EXPECT_EQ(a.action, model.actions[c]);
    EXPECT_EQ(a.probability, belief.probabilities[c]);
    ASSERT_EQ(a.joints.size(), 6u * joints.size());
    for (std::size_t k = 0; k < a.joints.size(); ++k) {
      const auto& g = a.joints[k];
      const Eigen::Vector3d mean(g.mean.x, g.mean.y, g.mean.z);
      ASSERT_TRUE(mean.allFinite());
      Eigen::Matrix3d cov;
      for (int r = 0; r < 3; ++r) {
        for (int q = 0; q < 3; ++q) cov(r, q) = g.covariance[static_cast<std::size_t>(3 * r + q)];
      }
      ASSERT_TRUE(cov.allFinite());
      EXPECT_LT((cov - cov.transpose()).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues().minCoeff(), 0.0);
      if (k < joints.size()) step0[k] += a.probability * mean;
    }
  }
  // One step (67 ms) ahead the person is still near where they were.
  for (std::size_t j = 0; j < joints.size(); ++j) {
    for (const auto& sj : s.joints) {
      if (sj.name != joints[j]) continue;
      EXPECT_LT((step0[j] - Eigen::Vector3d(sj.position.x, sj.position.y, sj.position.z)).norm(), 0.25)
          << joints[j] << " at stamp " << msg::ToNanoseconds(s.header.stamp);
      ++*checked_steps;
    }
  }
}

// Within a body, stamps keep the recorded spacing (scaled by rate 1); one
// body per played sequence.
void ExpectRecordedSpacing(const std::map<int64_t, msg::HumanSkeleton>& skeletons, const intent::SkeletonSequence& seq0) {
  std::map<uint32_t, std::vector<int64_t>> by_body;
  for (const auto& [stamp, s] : skeletons) by_body[s.body_id].push_back(stamp);
  EXPECT_EQ(by_body.size(), kPlayed.size());
  const auto& body1 = by_body[1];
  ASSERT_EQ(body1.size(), static_cast<std::size_t>(seq0.time.size()));
  EXPECT_NEAR((body1.back() - body1.front()) * 1e-9, seq0.time(seq0.time.size() - 1) - seq0.time(0), 1e-6);
}

// The service's own counters: nothing rejected, at least `matched` frames
// accepted. Diagnostics come once a second: wait for the one that counts
// every output seen (on a loaded machine the newest may still be older).
void ExpectCountersCoverTheOutputs(CellHarness& cell, int matched) {
  const auto accepted = [&] { return cell.DiagNumber("intent", "frames_accepted"); };
  cell.SpinUntil([&] { return accepted() >= matched; }, 5s);
  EXPECT_EQ(cell.Diag("intent", "frames_rejected"), "0");
  EXPECT_GE(accepted(), matched);
  EXPECT_EQ(cell.Diag("intent", "rejected/" + kSkeletonTopic), "0");
  EXPECT_FALSE(cell.Diag("intent", "cycle_time_p99_s").empty());
}

TEST_F(IntentServiceTest, ReplayedSequencesGetABeliefAndAPredictionPerSkeleton) {
  CellHarness cell("intent-replay", dds::Vendor::kCyclone, 11, "", /*with_intent=*/false);
  ASSERT_TRUE(cell.ready());
  framework::Node& node = cell.node();
  Observed seen;
  seen.Subscribe(node);
  const auto& skeletons = seen.skeletons;
  const auto& beliefs = seen.beliefs;
  const auto& predictions = seen.predictions;
  const std::vector<std::string>& joints = model_->config.joints.joints;
  cell.Configure("intent", cell.WriteFile("intent.yaml", IntentConfigText(joints, 15.0)));
  cell.Start("intent");
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.State("intent") == "active"; }, 30s)) << cell.Logs("intent");

  // The recording comes from the other vendor.
  cell.Configure("perception", cell.WriteFile("perception.yaml", ReplayConfigText()));
  cell.SetVendor("perception", dds::Vendor::kFastDds);
  cell.Start("perception");
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.Diag("perception", "replay_finished") == "true"; }, 60s))
      << cell.Logs("perception");
  cell.SpinFor(1500ms);  // last outputs and diagnostics

  // Every played frame was published (all Florence joints are detected).
  int frames = 0;
  for (const auto& s : played_->sequences) {
    if (std::find(kPlayed.begin(), kPlayed.end(), s.id) != kPlayed.end()) frames += static_cast<int>(s.time.size());
  }
  EXPECT_EQ(cell.Diag("perception", "published"), std::to_string(frames));
  ASSERT_GE(static_cast<int>(skeletons.size()), frames - 2) << "observer missed skeletons";
  EXPECT_EQ(seen.duplicate_outputs, 0);

  // The first frame of the first sequence: renamed joints, moved into W.
  const msg::HumanSkeleton& first = skeletons.begin()->second;
  EXPECT_EQ(first.body_id, 1u);
  const auto& seq0 = *std::find_if(played_->sequences.begin(), played_->sequences.end(),
                                   [](const intent::SkeletonSequence& s) { return s.id == kPlayed[0]; });
  const int hand_r = intent::JointIndices(played_->joint_names, {"hand_r"})[0];
  bool found_hand = false;
  for (const auto& j : first.joints) {
    if (j.name != "hand_r") continue;
    found_hand = true;
    const Eigen::Vector3d p_W(j.position.x, j.position.y, j.position.z);
    const Eigen::Vector3d p_S = seq0.positions.row(0).segment<3>(3 * hand_r).transpose();
    EXPECT_LT((p_W - (p_S + kSensorInWorld)).norm(), 1e-9);
  }
  EXPECT_TRUE(found_hand);

  // A belief and a prediction for (nearly) every skeleton, same stamp and body.
  int matched = 0, checked_steps = 0;
  for (const auto& [stamp, s] : skeletons) {
    const auto b = beliefs.find(stamp);
    const auto p = predictions.find(stamp);
    if (b == beliefs.end() || p == predictions.end()) continue;
    ++matched;
    ASSERT_NO_FATAL_FAILURE(CheckOutputs(*model_, joints, s, b->second, p->second, &checked_steps));
  }
  EXPECT_GE(matched, static_cast<int>(skeletons.size()) - 2) << "skeletons without a belief and prediction";
  std::cout << frames << " frames replayed, " << skeletons.size() << " skeletons seen, " << matched
            << " with a belief and a prediction" << std::endl;
  EXPECT_EQ(checked_steps, matched * static_cast<int>(joints.size()));
  // Every output belongs to a published skeleton (the observer may have
  // missed a few of those, never more than the count above allows).
  int unknown_stamps = 0;
  for (const auto& [stamp, b] : beliefs) unknown_stamps += skeletons.count(stamp) ? 0 : 1;
  EXPECT_LE(unknown_stamps, frames - static_cast<int>(skeletons.size()));

  ExpectRecordedSpacing(skeletons, seq0);
  ExpectCountersCoverTheOutputs(cell, matched);
  cell.Stop();
}

msg::HumanSkeleton Skeleton(uint32_t body, const std::vector<std::string>& names, const msg::Time& stamp) {
  msg::HumanSkeleton s;
  s.header.stamp = stamp;
  s.header.frame_id = "world";
  s.body_id = body;
  s.confidence = 1.0;
  for (std::size_t j = 0; j < names.size(); ++j) {
    msg::HumanJoint joint;
    joint.name = names[j];
    joint.position.x = 1.0 + 0.01 * static_cast<double>(j);
    joint.position.y = 0.1 * static_cast<double>(j % 3);
    joint.position.z = 1.0 + 0.05 * static_cast<double>(j);
    joint.confidence = 1.0;
    s.joints.push_back(joint);
  }
  return s;
}

// Writes a skeleton and gives the service time to answer.
void Send(CellHarness& cell, dds::Writer<msg::HumanSkeleton>& w, const msg::HumanSkeleton& s) {
  ASSERT_TRUE(w.Write(s));
  cell.SpinFor(60ms);
}

// Three good skeletons of body 500; garbage the boundary refuses (NaN, no
// joints, a duplicate joint) and the core refuses (no model joint, one
// missing, one at (0, 0, 0)); a fourth good one; then a backwards stamp on
// the same writer (boundary) and an older stamp for body 500 from writer b
// (core).
void SendGoodAndGarbage(CellHarness& cell, dds::Writer<msg::HumanSkeleton>& a, dds::Writer<msg::HumanSkeleton>& b,
                        const std::vector<std::string>& joints, const msg::Time& b_last_stamp) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 3; ++i) Send(cell, a, Skeleton(500, joints, msg::Now()));  // good: 3 outputs

  msg::HumanSkeleton bad = Skeleton(501, joints, msg::Now());
  bad.joints[2].position.y = nan;  // boundary check: non-finite
  Send(cell, a, bad);
  bad = Skeleton(502, {}, msg::Now());  // boundary check: no joints
  Send(cell, a, bad);
  bad = Skeleton(503, joints, msg::Now());
  bad.joints.push_back(bad.joints[0]);  // boundary check: duplicate joint name
  Send(cell, a, bad);
  std::vector<std::string> wrong = joints;
  for (auto& n : wrong) n = "openpose_" + n;
  Send(cell, a, Skeleton(504, wrong, msg::Now()));  // core: no model joint
  bad = Skeleton(505, joints, msg::Now());
  bad.joints.pop_back();  // core: one model joint missing
  Send(cell, a, bad);
  bad = Skeleton(506, joints, msg::Now());
  bad.joints[1].position = {};  // core: (0, 0, 0) is "not detected"
  Send(cell, a, bad);
  const msg::Time last_good_stamp = msg::Now();
  Send(cell, a, Skeleton(500, joints, last_good_stamp));  // good: output 4
  // Backwards stamp on the same writer: boundary check.
  Send(cell, a, Skeleton(507, joints, msg::TimeFromSeconds(msg::ToSeconds(msg::Now()) - 1.0)));
  // Another writer (a stamp after its own last one passes the boundary
  // check) repeats body 500 at an older stamp: the core rejects it.
  const double older = 0.5 * (msg::ToSeconds(b_last_stamp) + msg::ToSeconds(last_good_stamp));
  Send(cell, b, Skeleton(500, joints, msg::TimeFromSeconds(older)));
}

// A best-effort sample from a Fast DDS writer can be lost while the Cyclone
// reader has not yet matched it, even after the writer has matched the
// reader (../shared/docs/DDS-NOTES.md), and so can the service's answers
// to the observer. So the test waits until a probe body from writer `w`
// gets both a belief and a prediction back; returns the probe's stamp (0
// when no answer came within 30 s).
double WaitUntilHeard(CellHarness& cell, dds::Writer<msg::HumanSkeleton>& w, uint32_t body,
                      const std::vector<std::string>& joints, const std::multiset<uint32_t>& beliefs,
                      const std::multiset<uint32_t>& predictions) {
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < until) {
    const msg::Time stamp = msg::Now();
    if (!w.Write(Skeleton(body, joints, stamp))) return 0;
    cell.SpinFor(100ms);
    if (beliefs.count(body) > 0 && predictions.count(body) > 0) return msg::ToSeconds(stamp);
  }
  return 0;
}

TEST_F(IntentServiceTest, GarbageSkeletonsAreRejectedCountedAndProduceNothing) {
  CellHarness cell("intent-garbage", dds::Vendor::kFastDds, 12, "", /*with_intent=*/false);
  ASSERT_TRUE(cell.ready());
  framework::Node& node = cell.node();
  std::multiset<uint32_t> belief_bodies, prediction_bodies;
  node.Subscribe(framework::topics::ActionBelief(),
                 std::function<void(const msg::ActionBelief&, const dds::SampleInfo&)>(
                     [&](const msg::ActionBelief& b, const dds::SampleInfo&) { belief_bodies.insert(b.body_id); }));
  node.Subscribe(framework::topics::HumanPrediction(),
                 std::function<void(const msg::HumanPrediction&, const dds::SampleInfo&)>(
                     [&](const msg::HumanPrediction& p, const dds::SampleInfo&) {
                       prediction_bodies.insert(p.body_id);
                     }));
  const auto topic = framework::topics::HumanSkeleton();
  dds::Writer<msg::HumanSkeleton> a(cell.participant(), topic.name, topic.qos);
  dds::Writer<msg::HumanSkeleton> b(cell.participant(), topic.name, topic.qos);

  const std::vector<std::string>& joints = model_->config.joints.joints;
  cell.Configure("intent", cell.WriteFile("intent.yaml", IntentConfigText(joints, 15.0)));
  cell.SetVendor("intent", dds::Vendor::kCyclone);
  cell.Start("intent");
  ASSERT_TRUE(cell.SpinUntil([&] {
    return cell.State("intent") == "active" && a.MatchedReaders() > 0 && b.MatchedReaders() > 0;
  }, 30s)) << cell.Logs("intent");
  // Probe bodies 600 (writer a) and 601 (writer b) until the service
  // answers each: from then on nothing either writer sends is lost.
  ASSERT_GT(WaitUntilHeard(cell, a, 600, joints, belief_bodies, prediction_bodies), 0.0) << cell.Logs("intent");
  const double b_probe = WaitUntilHeard(cell, b, 601, joints, belief_bodies, prediction_bodies);
  ASSERT_GT(b_probe, 0.0) << cell.Logs("intent");
  // The probes' counts reach the diagnostics within the service's timer
  // period (body_timeout / 2) and the diagnostics period.
  auto diag = [&](const std::string& key) { return cell.DiagNumber("intent", key); };
  ASSERT_TRUE(cell.SpinUntil([&] { return diag("frames_accepted") >= 2; }, 10s));
  cell.SpinFor(1500ms);
  const double accepted_before = diag("frames_accepted");
  ASSERT_GE(accepted_before, 2);
  EXPECT_EQ(diag("frames_rejected"), 0);
  EXPECT_EQ(diag("rejected/" + kSkeletonTopic), 0);
  std::set<uint32_t> answered;  // bodies answered, probes aside
  belief_bodies.clear();
  prediction_bodies.clear();

  ASSERT_NO_FATAL_FAILURE(SendGoodAndGarbage(cell, a, b, joints, msg::TimeFromSeconds(b_probe)));
  cell.SpinFor(1000ms);

  EXPECT_TRUE(cell["intent"].Running()) << cell.Logs("intent");
  for (uint32_t body : belief_bodies) answered.insert(body);
  for (uint32_t body : prediction_bodies) answered.insert(body);
  answered.erase(600);
  answered.erase(601);
  EXPECT_EQ(answered, std::set<uint32_t>({500}));  // no garbage body got an output
  EXPECT_EQ(belief_bodies.count(500), 4u);
  EXPECT_EQ(prediction_bodies.count(500), 4u);
  EXPECT_EQ(diag("rejected/" + kSkeletonTopic), 4);  // nan, empty, duplicate, backwards
  EXPECT_EQ(diag("frames_rejected/missing_joint"), 3);
  EXPECT_EQ(diag("frames_rejected/stamp_not_increasing"), 1);
  EXPECT_EQ(diag("frames_rejected"), 4);
  EXPECT_EQ(diag("frames_accepted") - accepted_before, 4);
  EXPECT_NE(cell.Diag("intent", "last_rejected_frame").find("not after body 500"), std::string::npos)
      << cell.Diag("intent", "last_rejected_frame");

  // Still serving after the garbage.
  ASSERT_NO_FATAL_FAILURE(Send(cell, a, Skeleton(500, joints, msg::Now())));
  cell.SpinFor(500ms);
  EXPECT_EQ(belief_bodies.count(500), 5u);

  cell.Stop();
  // Each kind of core rejection is logged once, then only counted.
  const std::string err = cell.Logs("intent");
  auto count = [&](const std::string& text) {
    int n = 0;
    for (std::size_t at = err.find(text); at != std::string::npos; at = err.find(text, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("rejected (missing_joint)"), 1) << err;
  EXPECT_EQ(count("rejected (stamp_not_increasing)"), 1) << err;
}

// intent.predictor constant-velocity: the prediction is the baseline's (one
// component, the model's horizon and rate, a straight line continued), the
// belief stays the model's.
TEST_F(IntentServiceTest, ABaselinePredictorReplacesThePredictionNotTheBelief) {
  CellHarness cell("intent-baseline", dds::Vendor::kCyclone, 14, "", /*with_intent=*/false);
  ASSERT_TRUE(cell.ready());
  framework::Node& node = cell.node();
  std::optional<msg::ActionBelief> belief;
  std::optional<msg::HumanPrediction> prediction;
  node.Subscribe(framework::topics::ActionBelief(),
                 std::function<void(const msg::ActionBelief&, const dds::SampleInfo&)>(
                     [&](const msg::ActionBelief& b, const dds::SampleInfo&) { belief = b; }));
  node.Subscribe(framework::topics::HumanPrediction(),
                 std::function<void(const msg::HumanPrediction&, const dds::SampleInfo&)>(
                     [&](const msg::HumanPrediction& p, const dds::SampleInfo&) { prediction = p; }));
  const std::vector<std::string>& joints = model_->config.joints.joints;
  cell.Configure("intent", cell.WriteFile("intent.yaml", IntentConfigText(joints, 15.0) + "  predictor: constant-velocity\n"));
  cell.SetVendor("intent", dds::Vendor::kFastDds);
  cell.Start("intent");
  auto& w = node.Advertise(framework::topics::HumanSkeleton());
  ASSERT_TRUE(cell.SpinUntil([&] { return w.MatchedReaders() > 0; }, 30s)) << cell.Logs("intent");
  // Every joint moves at 0.3 m/s along x, at 30 Hz for 0.5 s.
  const double t0 = msg::ToSeconds(msg::Now());
  msg::HumanSkeleton last;
  for (int k = 0; k < 15; ++k) {
    const double t = t0 + k / 30.0;
    last = Skeleton(700, joints, msg::TimeFromSeconds(t));
    for (auto& j : last.joints) j.position.x += 0.3 * (t - t0);
    ASSERT_TRUE(w.Write(last));
    cell.SpinFor(33ms);
  }
  cell.SpinFor(300ms);
  ASSERT_TRUE(prediction.has_value()) << cell.Logs("intent");
  ASSERT_TRUE(belief.has_value());
  EXPECT_EQ(belief->actions, model_->actions);
  ASSERT_EQ(prediction->actions.size(), 1u);
  EXPECT_EQ(prediction->actions[0].action, "constant_velocity");
  EXPECT_EQ(prediction->num_steps, static_cast<uint32_t>(model_->config.horizon));
  EXPECT_NEAR(prediction->time_step, 1.0 / model_->config.rate, 1e-12);
  // Step k (0-based) is (k + 1) / rate after the last observation: x moved on at 0.3 m/s.
  const std::size_t J = joints.size();
  const int k = static_cast<int>(prediction->num_steps) - 1;
  const double tau = (k + 1) * prediction->time_step;
  EXPECT_NEAR(prediction->actions[0].joints[static_cast<std::size_t>(k) * J].mean.x, last.joints[0].position.x + 0.3 * tau,
              1e-6);
  cell.Stop();
}

TEST_F(IntentServiceTest, AModelThatDoesNotMatchTheConfigurationIsRefused) {
  struct Case {
    std::string config;
    std::string expected;
  };
  std::vector<std::string> other = model_->config.joints.joints;
  other.back() = "hand_right";
  const std::vector<Case> cases = {
      {IntentConfig("joints.yaml", other, 15.0), "do not match the configured joints [" },
      {IntentConfig("rate.yaml", model_->config.joints.joints, 30.0),
       "model rate 15 Hz does not match the configured rate 30 Hz"},
      {IntentConfig("missing.yaml", model_->config.joints.joints, 15.0, "nothing_here.model"), "cannot open"},
      {Write("nomodel.yaml", "intent:\n  joints: [a]\n  rate_hz: 15\n"), "key 'intent.model'"},
  };
  for (const Case& c : cases) {
    Process p({BinPath("iplan-intent"), "--config", c.config, "--domain", std::to_string(UniqueDomain(13))});
    const auto rc = p.Wait(30s);
    ASSERT_TRUE(rc.has_value()) << c.config << ": service did not exit";
    EXPECT_EQ(*rc, 2) << p.Stderr();
    EXPECT_NE(p.Stderr().find(c.config), std::string::npos) << p.Stderr();
    EXPECT_NE(p.Stderr().find(c.expected), std::string::npos) << p.Stderr();
  }
}

}  // namespace
}  // namespace iplan::testing
