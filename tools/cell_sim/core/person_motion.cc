#include "tools/cell_sim/core/person_motion.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "services/perception/core/person_body.h"
#include "services/perception/core/skeleton_replay.h"

namespace iplan::cell_sim {
namespace {

// The synthetic person's body (services/perception/core/person_body.h).
using perception::ArmElbow;
using perception::kMaxReach;
using perception::kNeckToHead;
using perception::kShoulderBelowNeck;
using perception::kTorsoToNeck;
using perception::MinJerk;

// Where the sweep puts the hand at t (s), the script having it at `own`;
// nullopt outside the sweep.
std::optional<Eigen::Vector3d> SweptHand(const HandSweep& w, double t, const Eigen::Vector3d& own) {
  const double u = t - w.start;
  if (u < 0 || u > 2 * w.approach + w.duration) return std::nullopt;
  if (u < w.approach) return Eigen::Vector3d(own + MinJerk(u / w.approach) * (w.from_W - own));
  if (u < w.approach + w.duration) return Eigen::Vector3d(w.from_W + MinJerk((u - w.approach) / w.duration) * (w.to_W - w.from_W));
  return Eigen::Vector3d(w.to_W + MinJerk((u - w.approach - w.duration) / w.approach) * (own - w.to_W));
}

int BodyJoint(const std::vector<std::string>& body_joints, const std::string& name) {
  const auto it = std::find(body_joints.begin(), body_joints.end(), name);
  if (it == body_joints.end()) throw std::invalid_argument("a hand sweep needs the body joint '" + name + "'");
  return static_cast<int>(it - body_joints.begin());
}

void CheckArguments(double rate_hz, double duration, double noise_std) {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) throw std::invalid_argument("rate_hz must be > 0");
  if (!(duration > 0) || !std::isfinite(duration)) throw std::invalid_argument("duration must be > 0 s");
  if (!(noise_std >= 0) || !std::isfinite(noise_std)) throw std::invalid_argument("noise_std must be >= 0 m");
}

const intent::SkeletonSequence& FindSequence(const intent::SkeletonDataset& data, const std::string& id) {
  for (const auto& s : data.sequences) {
    if (s.id == id) return s;
  }
  throw std::invalid_argument("no sequence '" + id + "' in the recordings");
}

int JointColumn(const intent::SkeletonDataset& data, const std::string& name) {
  const auto it = std::find(data.joint_names.begin(), data.joint_names.end(), name);
  if (it == data.joint_names.end()) throw std::invalid_argument("the recordings have no joint '" + name + "'");
  return static_cast<int>(it - data.joint_names.begin());
}

void AddNoise(double noise_std, uint64_t seed, PersonStream* s) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  s->observed.resize(s->truth.size());
  for (std::size_t i = 0; i < s->truth.size(); ++i) {
    Eigen::Matrix3Xd o = s->truth[i];
    for (Eigen::Index j = 0; j < o.cols(); ++j) {
      for (int a = 0; a < 3; ++a) o(a, j) += noise_std * n(rng);
    }
    s->observed[i] = std::move(o);
  }
}

}  // namespace

std::string HandSweep::Validate() const {
  if (!from_W.allFinite() || !to_W.allFinite() || !std::isfinite(start)) return "hand sweep: from, to and start must be finite";
  if (!(approach > 0) || !std::isfinite(approach)) return "hand sweep: approach must be > 0 s";
  if (!(duration > 0) || !std::isfinite(duration)) return "hand sweep: duration must be > 0 s";
  return "";
}

Eigen::Isometry3d RecordingPose(const intent::SkeletonDataset& data, const std::string& sequence,
                                const RecordedPlacement& placement) {
  const intent::SkeletonSequence& seq = FindSequence(data, sequence);
  const int l = JointColumn(data, "shoulder_l"), r = JointColumn(data, "shoulder_r");
  Eigen::Vector3d c_S = Eigen::Vector3d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < seq.positions.rows(); ++i) {
    const Eigen::RowVectorXd pl = seq.positions.row(i).segment(3 * l, 3), pr = seq.positions.row(i).segment(3 * r, 3);
    if (!intent::JointDetected(pl) || !intent::JointDetected(pr)) continue;
    c_S += 0.5 * (pl + pr).transpose();
    ++n;
  }
  if (n == 0) throw std::invalid_argument("sequence '" + sequence + "' never shows both shoulders");
  c_S /= n;
  Eigen::Matrix3d R_WS0;
  R_WS0 << 0, 0, 1,  //
      -1, 0, 0,      //
      0, -1, 0;
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();
  X_WS.linear() = Eigen::AngleAxisd(placement.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_WS0;
  X_WS.translation() = placement.shoulder_centre_W - X_WS.linear() * c_S;
  return X_WS;
}

namespace {

// Which body joints come from the recording (column into the replay's
// joints), which are derived from the shoulders (head, neck, torso).
struct BodyFromRecording {
  std::vector<int> column;
  int neck = -1, head = -1, torso = -1, shoulder_l = -1, shoulder_r = -1;
  bool derives() const { return neck >= 0 || head >= 0 || torso >= 0; }
};

BodyFromRecording MapBodyJoints(const std::vector<std::string>& body_joints, const std::vector<std::string>& names,
                                const std::string& file) {
  BodyFromRecording m;
  m.column.assign(body_joints.size(), -1);
  for (std::size_t b = 0; b < body_joints.size(); ++b) {
    const auto it = std::find(names.begin(), names.end(), body_joints[b]);
    if (it != names.end()) {
      m.column[b] = static_cast<int>(it - names.begin());
    } else if (body_joints[b] == "neck") {
      m.neck = static_cast<int>(b);
    } else if (body_joints[b] == "head") {
      m.head = static_cast<int>(b);
    } else if (body_joints[b] == "torso") {
      m.torso = static_cast<int>(b);
    } else {
      throw std::invalid_argument("body joint '" + body_joints[b] + "' is not in " + file +
                                  " (after joint_map) and cannot be derived (only head, neck and torso are)");
    }
    if (body_joints[b] == "shoulder_l") m.shoulder_l = static_cast<int>(b);
    if (body_joints[b] == "shoulder_r") m.shoulder_r = static_cast<int>(b);
  }
  if (m.derives() && (m.shoulder_l < 0 || m.shoulder_r < 0 || m.column[m.shoulder_l] < 0 || m.column[m.shoulder_r] < 0)) {
    throw std::invalid_argument("head, neck and torso are derived from shoulder_l and shoulder_r, which " + file +
                                " lacks");
  }
  return m;
}

// Recorded frames in W, undetected joints held; before every joint has been
// seen once, frames are skipped.
void ReplayFrames(perception::SkeletonReplay* replay, std::vector<double>* times, std::vector<Eigen::Matrix3Xd>* frames) {
  const std::vector<std::string>& names = replay->published_joint_names();
  std::vector<bool> seen(names.size(), false);
  Eigen::Matrix3Xd last = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(names.size()));
  perception::ReplayFrame f;
  while (replay->Next(1e300, &f)) {
    for (const auto& j : f.joints) {
      const auto it = std::find(names.begin(), names.end(), j.name);
      const std::size_t k = static_cast<std::size_t>(it - names.begin());
      last.col(static_cast<Eigen::Index>(k)) = j.position_W;
      seen[k] = true;
    }
    if (std::find(seen.begin(), seen.end(), false) != seen.end()) continue;
    if (!times->empty() && !(f.play_time > times->back())) continue;
    times->push_back(f.play_time);
    frames->push_back(last);
  }
}

// The body at recording time r: the recorded joints interpolated, the
// derived ones placed from the shoulders.
Eigen::Matrix3Xd BodyAt(const BodyFromRecording& m, const std::vector<double>& times,
                        const std::vector<Eigen::Matrix3Xd>& frames, double r, std::size_t* seg) {
  while (*seg + 1 < times.size() && times[*seg + 1] <= r) ++*seg;
  const std::size_t i = *seg;
  Eigen::Matrix3Xd rec = frames[i];
  if (i + 1 < times.size() && r > times[i]) {
    const double u = (r - times[i]) / (times[i + 1] - times[i]);
    rec = (1 - u) * frames[i] + u * frames[i + 1];
  }
  Eigen::Matrix3Xd p(3, static_cast<Eigen::Index>(m.column.size()));
  for (std::size_t b = 0; b < m.column.size(); ++b) {
    if (m.column[b] >= 0) p.col(static_cast<Eigen::Index>(b)) = rec.col(m.column[b]);
  }
  if (m.derives()) {
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d n_W = 0.5 * (p.col(m.shoulder_l) + p.col(m.shoulder_r)) + kShoulderBelowNeck * up;
    if (m.neck >= 0) p.col(m.neck) = n_W;
    if (m.head >= 0) p.col(m.head) = n_W + kNeckToHead * up;
    if (m.torso >= 0) p.col(m.torso) = n_W - kTorsoToNeck * up;
  }
  return p;
}

}  // namespace

PersonStream RecordedPersonStream(const intent::SkeletonDataset& data, const std::string& file,
                                  const std::string& sequence, const std::map<std::string, std::string>& joint_map,
                                  const RecordedPlacement& placement, const std::vector<std::string>& body_joints,
                                  double rate_hz, double duration, double noise_std, uint64_t seed) {
  CheckArguments(rate_hz, duration, noise_std);
  if (!(placement.clip_start >= 0) || !(placement.delay >= 0)) {
    throw std::invalid_argument("clip_start and delay must be >= 0 s");
  }
  // The perception service's replay of this one sequence.
  intent::SkeletonDataset one;
  one.joint_names = data.joint_names;
  one.sequences.push_back(FindSequence(data, sequence));
  perception::SkeletonReplayParams rp;
  rp.file = file;
  rp.sequences = {sequence};
  rp.joint_map = joint_map;
  rp.X_WS = RecordingPose(data, sequence, placement);
  perception::SkeletonReplay replay(rp, std::move(one));
  const BodyFromRecording map = MapBodyJoints(body_joints, replay.published_joint_names(), file);
  std::vector<double> times;
  std::vector<Eigen::Matrix3Xd> frames;
  ReplayFrames(&replay, &times, &frames);
  if (frames.empty()) throw std::invalid_argument("sequence '" + sequence + "' never shows every joint of " + file);

  PersonStream s;
  s.joint_names = body_joints;
  s.rate_hz = rate_hz;
  const int n = static_cast<int>(std::floor(duration * rate_hz)) + 1;
  const double t0 = times.front();
  std::size_t seg = 0;
  for (int i = 0; i < n; ++i) {
    // Recording time of this frame: the first pose until the delay is over.
    const double r = t0 + placement.clip_start + std::max(0.0, i / rate_hz - placement.delay);
    s.truth.push_back(BodyAt(map, times, frames, r, &seg));
  }
  AddNoise(noise_std, seed, &s);
  return s;
}

PersonStream SyntheticPersonStream(const perception::SyntheticPersonParams& person, const SyntheticPlacement& placement,
                                   const std::vector<std::string>& body_joints, double rate_hz, double duration,
                                   double noise_std, uint64_t seed) {
  CheckArguments(rate_hz, duration, noise_std);
  int hand = -1, elbow = -1, shoulder = -1;
  if (placement.sweep) {
    if (const std::string why = placement.sweep->Validate(); !why.empty()) throw std::invalid_argument(why);
    const std::string side = placement.sweep->right_hand ? "_r" : "_l";
    hand = BodyJoint(body_joints, "hand" + side);
    elbow = BodyJoint(body_joints, "elbow" + side);
    shoulder = BodyJoint(body_joints, "shoulder" + side);
  }
  perception::SyntheticPersonParams p = person;
  p.torso_W += placement.torso_offset_W;
  p.facing_yaw += placement.yaw;
  p.loop = false;
  perception::SyntheticPerson sim(p);
  // Before the script starts the person idles in the last step's action, as
  // the synthetic person does before its first episode.
  sim.StartScript(placement.script_start);

  PersonStream s;
  s.joint_names = body_joints;
  s.rate_hz = rate_hz;
  const int n = static_cast<int>(std::floor(duration * rate_hz)) + 1;
  std::vector<int> index;
  for (int i = 0; i < n; ++i) {
    const std::vector<perception::JointSample> pose = sim.TruePose(i / rate_hz);
    if (index.empty()) {
      for (const auto& name : body_joints) {
        const auto it = std::find_if(pose.begin(), pose.end(), [&](const auto& j) { return j.name == name; });
        if (it == pose.end()) throw std::invalid_argument("body joint '" + name + "' is not a joint of the synthetic person");
        index.push_back(static_cast<int>(it - pose.begin()));
      }
    }
    Eigen::Matrix3Xd q(3, static_cast<Eigen::Index>(body_joints.size()));
    for (std::size_t b = 0; b < body_joints.size(); ++b) {
      q.col(static_cast<Eigen::Index>(b)) = pose[static_cast<std::size_t>(index[b])].position_W;
    }
    if (placement.sweep) {
      if (const auto h = SweptHand(*placement.sweep, i / rate_hz, q.col(hand))) {
        const Eigen::Vector3d s_W = q.col(shoulder), d = *h - s_W;
        const Eigen::Vector3d h_W = d.norm() > kMaxReach ? Eigen::Vector3d(s_W + d.normalized() * kMaxReach) : *h;
        q.col(hand) = h_W;
        q.col(elbow) = ArmElbow(s_W, h_W);
      }
    }
    s.truth.push_back(std::move(q));
  }
  AddNoise(noise_std, seed, &s);
  return s;
}

}  // namespace iplan::cell_sim
