// The shared-space suite of the interaction benchmark (`iplan eval
// interaction --suite shared-space`, interaction_benchmark.h): hand-overs,
// the parts bin, co-assembly and crossings, every scenario checked to bring
// the person within reach of the robot's path before it is run.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

#include "tools/cell_sim/core/interaction_benchmark.h"
#include "tools/cell_sim/core/person_motion.h"
#include "tools/cell_sim/core/scenario_draws.h"
#include "iplan/collision/robot_model.h"

namespace iplan::cell_sim {
namespace internal {
namespace {

// ---- The shared-space suite ----

// What every shared-space draw needs from the setup.
struct SharedSpaceCell {
  const BenchmarkSetup* setup = nullptr;
  const planning::Planner* planner = nullptr;
  std::vector<NamedPose> poses;
  Eigen::VectorXd home;
  Eigen::Matrix3d R_home;
  const GraphTask* hand_over = nullptr;
  const GraphTask* fetch_left = nullptr;
  const perception::ActionMotion* reach_parts = nullptr;  // the person's reach into the parts tray
  const perception::ActionMotion* assemble = nullptr;     // the person's work at the assembly area
  perception::ActionMotion rest;                          // what the person does before and after
  bool rest_is_cells = false;                             // rest is one of the cell's actions
  std::string script;                                     // the cell's script, comma-separated
  std::vector<std::string> subjects;
  std::map<std::string, std::vector<const intent::SkeletonSequence*>> by_subject;
};

// The flange point at q (the reach's target point), W.
Eigen::Vector3d FlangePoint(const planning::Planner& planner, const Eigen::VectorXd& q) {
  return EndEffectorPose(planner, q).translation();
}

std::string Join(const std::vector<perception::ScriptStep>& script) {
  std::string out;
  for (const auto& s : script) out += (out.empty() ? "" : ",") + s.action;
  return out;
}

// The synthetic person placed with its torso at torso_W (turned by yaw from
// the configured facing): which hand is on the side of p_W.
bool RightHandTowards(const perception::SyntheticPersonParams& person, double yaw, const Eigen::Vector3d& torso_W,
                      const Eigen::Vector3d& p_W) {
  // The person frame's y is to their left.
  const Eigen::Vector3d left_W =
      Eigen::AngleAxisd(person.facing_yaw + yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * Eigen::Vector3d::UnitY();
  return (p_W - torso_W).dot(left_W) < 0;
}

// The synthetic person at torso_W doing `action` (replacing the cell's of
// its name or added to them) from script_start for `seconds`, then resting.
void SharedSynthetic(const SharedSpaceCell& c, const Eigen::Vector3d& torso_W, double yaw, double script_start,
                     const perception::ActionMotion& action, double seconds, ScenarioSpec* s) {
  s->source = "synthetic";
  s->subject = "synthetic";
  s->placement_W = torso_W;
  s->yaw = yaw;
  s->delay = script_start;
  s->person_actions = {action};
  if (!c.rest_is_cells) s->person_actions.push_back(c.rest);
  s->person_script = {{action.name, seconds}, {c.rest.name, 1.0}};
  s->sequence = Join(s->person_script);
}

// A recorded person whose hands' farthest reach towards the robot (smallest
// x over both hands, in the task's first `window` s) falls on target_W
// (horizontally; shoulders at the synthetic person's height, no nearer the
// robot than x = 1.0 m, the table's far edge being at 1.05 m).
void SharedRecorded(const SharedSpaceCell& c, int recorded, const Eigen::Vector3d& target_W, Draws* d,
                    ScenarioSpec* s) {
  const BenchmarkSetup& setup = *c.setup;
  DrawRecordedPerson(c.subjects, c.by_subject, recorded, d, s);  // subject, sequence, yaw, clip, delay
  const double t0 = setup.loop.task_start, t1 = t0 + setup.shared_space.window;
  const PersonStream provisional = MakePersonStream(setup, *s, t1 + 0.1);
  const auto& joints = setup.models.body->params().joints;
  std::vector<Eigen::Index> hands;
  for (const char* h : {"hand_l", "hand_r"}) {
    const auto it = std::find(joints.begin(), joints.end(), h);
    if (it != joints.end()) hands.push_back(it - joints.begin());
  }
  if (hands.empty()) throw std::invalid_argument("the shared-space suite needs the body joints hand_l or hand_r");
  Eigen::Vector3d reach(std::numeric_limits<double>::infinity(), 0.0, 0.0);
  for (int f = 0; f < provisional.num_frames(); ++f) {
    if (provisional.stamp(f) < t0 || provisional.stamp(f) > t1) continue;
    for (Eigen::Index h : hands) {
      const Eigen::Vector3d p = provisional.truth[static_cast<std::size_t>(f)].col(h);
      if (p.x() < reach.x()) reach = p;
    }
  }
  const Eigen::Vector3d shift(target_W.x() - reach.x(), target_W.y() - reach.y(), 0.0);
  s->placement_W += shift;
  s->placement_W.x() = std::max(s->placement_W.x(), 1.0);
}

// A reach whose flange target lies in box [lo, hi] (W, m), from a graph
// pose, as DrawReach; false when none of 20 tries is reachable and clear.
bool SharedReach(const SharedSpaceCell& c, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Draws* d,
                 ScenarioSpec* s) {
  const planning::Planner& planner = *c.planner;
  s->task = "reach";
  const NamedPose& start = c.poses[static_cast<std::size_t>(d->Index(c.poses.size()))];
  s->start = start.name;
  s->start_q = start.q;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const Eigen::Vector3d p(d->Uniform(lo.x(), hi.x()), d->Uniform(lo.y(), hi.y()), d->Uniform(lo.z(), hi.z()));
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(d->Uniform(-0.5, 0.5), Eigen::Vector3d::UnitZ()).toRotationMatrix() * c.R_home;
    const planning::IkResult ik = planner.SolveIk(p, Eigen::Quaterniond(R), c.home, d->Next());
    if (!ik.success) continue;
    if (planner.CalcClearance(ik.q) < planner.params().min_clearance + 0.02) continue;
    if ((ik.q - s->start_q).cwiseAbs().maxCoeff() < 0.3) continue;
    s->goal_q = ik.q;
    s->reach_p_WE = p;
    return true;
  }
  return false;
}

// The flange points along the straight joint path from start to goal at
// fractions u in [0.2, 0.8] (13 of them).
std::vector<Eigen::Vector3d> PathPoints(const planning::Planner& planner, const ScenarioSpec& s) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k <= 12; ++k) {
    const double u = 0.2 + 0.05 * k;
    points.push_back(FlangePoint(planner, s.start_q + u * (s.goal_q - s.start_q)));
  }
  return points;
}

// Hand-over: the person reaches for the part in the tool, just in front of and below the flange.
bool DrawHandOver(const SharedSpaceCell& c, bool synthetic, double yaw, Draws* d, ScenarioSpec* s, Eigen::Vector3d* target) {
  const planning::Planner& planner = *c.planner;
  const BenchmarkSetup& setup = *c.setup;
  const perception::SyntheticPersonParams& person = setup.person;
  DrawGraphTask({*c.hand_over}, c.poses, d, s);
  s->shared_point_W = FlangePoint(planner, s->goal_q);
  *target = s->shared_point_W + Eigen::Vector3d(d->Uniform(0.06, 0.16), d->Uniform(-0.05, 0.05), d->Uniform(-0.10, -0.02));
  if (synthetic) {
    const Eigen::Vector3d torso = person.torso_W + Eigen::Vector3d(d->Uniform(-0.15, -0.05), d->Uniform(-0.15, 0.05), 0.0);
    perception::ActionMotion a;
    a.name = "reach_hand_over";
    a.kind = perception::MotionKind::kReach;
    a.right_hand = RightHandTowards(person, yaw, torso, *target);
    a.target_W = *target;
    a.period = d->Uniform(2.5, 3.5);
    SharedSynthetic(c, torso, yaw, d->Uniform(0.0, 2.5), a, 2 * a.period, s);
  }
  return true;
}

// Parts-bin: into the bin under fetch_left's flange, or between it and the tray.
bool DrawPartsBin(const SharedSpaceCell& c, bool synthetic, double yaw, Draws* d, ScenarioSpec* s, Eigen::Vector3d* target) {
  const planning::Planner& planner = *c.planner;
  const BenchmarkSetup& setup = *c.setup;
  const perception::SyntheticPersonParams& person = setup.person;
  DrawGraphTask({*c.fetch_left}, c.poses, d, s);
  const Eigen::Vector3d flange = FlangePoint(planner, s->goal_q);
  const Eigen::Vector3d tray = c.reach_parts->target_W;
  const Eigen::Vector3d bin(flange.x(), flange.y(), tray.z() + 0.05);
  *target = tray + d->Uniform(0.3, 1.0) * (bin - tray);
  s->shared_point_W = *target;
  if (synthetic) {
    const Eigen::Vector3d torso = person.torso_W + Eigen::Vector3d(d->Uniform(-0.20, -0.08), d->Uniform(0.0, 0.15), 0.0);
    perception::ActionMotion a = *c.reach_parts;
    a.right_hand = RightHandTowards(person, yaw, torso, *target);
    a.target_W = *target;
    SharedSynthetic(c, torso, yaw, d->Uniform(0.0, 2.5), a, 2 * a.period, s);
  }
  return true;
}

// Co-assembly: the robot reaches to the near side of the person's assembly area.
bool DrawCoAssembly(const SharedSpaceCell& c, bool synthetic, double yaw, Draws* d, ScenarioSpec* s, Eigen::Vector3d* target) {
  const BenchmarkSetup& setup = *c.setup;
  const perception::SyntheticPersonParams& person = setup.person;
  if (!SharedReach(c, {0.60, -0.12, 0.24}, {0.72, 0.12, 0.34}, d, s)) return false;
  s->shared_point_W = s->reach_p_WE;
  *target = Eigen::Vector3d(s->reach_p_WE.x() + d->Uniform(0.14, 0.24), s->reach_p_WE.y() + d->Uniform(-0.06, 0.06),
                           c.assemble->target_W.z());
  if (synthetic) {
    const Eigen::Vector3d torso =
        person.torso_W + Eigen::Vector3d(d->Uniform(-0.15, -0.05),
                                         target->y() - c.assemble->target_W.y() + d->Uniform(-0.05, 0.05), 0.0);
    perception::ActionMotion a = *c.assemble;
    a.target_W = *target;
    // Assembling when the robot arrives (it is commanded at task_start),
    // for 3-6 s, then resting.
    SharedSynthetic(c, torso, yaw, d->Uniform(-2.0, 1.5), a, d->Uniform(3.0, 6.0), s);
  }
  return true;
}

// Crossing: the hand sweeps across the path's point nearest the person, mid-task.
bool DrawCrossing(const SharedSpaceCell& c, bool synthetic, double yaw, Draws* d, ScenarioSpec* s, Eigen::Vector3d* target) {
  const planning::Planner& planner = *c.planner;
  const BenchmarkSetup& setup = *c.setup;
  const perception::SyntheticPersonParams& person = setup.person;
  DrawGraphTask(setup.tasks, c.poses, d, s);
  const std::vector<Eigen::Vector3d> points = PathPoints(planner, *s);
  std::size_t k = 0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (points[i].x() > points[k].x()) k = i;
  }
  const Eigen::Vector3d crossing = points[k];
  if (crossing.x() < 0.40) return false;  // the path stays by the robot, out of the person's reach
  s->shared_point_W = crossing;
  *target = crossing;
  if (synthetic) {
    const Eigen::Vector3d along = points[std::min(k + 1, points.size() - 1)] - points[k > 0 ? k - 1 : 0];
    Eigen::Vector3d side = Eigen::Vector3d::UnitZ().cross(along);
    side = side.norm() > 1e-6 ? Eigen::Vector3d(side.normalized()) : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d torso(std::max(crossing.x() + d->Uniform(0.45, 0.55), 1.1),
                                crossing.y() + d->Uniform(-0.15, 0.15), person.torso_W.z());
    HandSweep w;
    const double half = d->Uniform(0.18, 0.28) * (d->Uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0);
    const Eigen::Vector3d lift(0, 0, d->Uniform(-0.04, 0.04));
    w.from_W = crossing + half * side + lift;
    w.to_W = crossing - half * side + lift;
    w.from_W.z() = std::max(w.from_W.z(), 0.08);
    w.to_W.z() = std::max(w.to_W.z(), 0.08);
    w.right_hand = RightHandTowards(person, yaw, torso, crossing);
    w.duration = d->Uniform(0.8, 1.4);
    w.approach = 0.6;
    w.start = setup.loop.task_start + d->Uniform(0.6, 2.2) - w.approach - 0.5 * w.duration;
    s->source = "synthetic";
    s->subject = "synthetic";
    s->placement_W = torso;
    s->yaw = yaw;
    s->delay = d->Uniform(-9.0, 2.0);  // the person's own script goes on, as in the default suite
    s->sequence = c.script;
    s->sweep = w;
  }
  return true;
}

// One draw of scenario s->index of `kind` (index into SharedSpaceKinds()),
// its person synthetic or recorded; false when the draw is unusable (a
// reach not found, a path the person cannot cross).
bool DrawShared(const SharedSpaceCell& c, int kind, bool synthetic, int recorded, Draws* d, ScenarioSpec* s) {
  const double yaw = d->Uniform(-0.2, 0.2);
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // where the person's hand is to go
  bool drawn = false;
  switch (kind) {
    case 0: drawn = DrawHandOver(c, synthetic, yaw, d, s, &target); break;
    case 1: drawn = DrawPartsBin(c, synthetic, yaw, d, s, &target); break;
    case 2: drawn = DrawCoAssembly(c, synthetic, yaw, d, s, &target); break;
    default: drawn = DrawCrossing(c, synthetic, yaw, d, s, &target); break;
  }
  if (!drawn) return false;
  // A recorded person's hands stay near their farthest reach much of the
  // time: it is put 0.10-0.25 m beyond the shared point (towards the
  // person), so that they come within reach of the path without holding its
  // goal for good.
  if (!synthetic) SharedRecorded(c, recorded, target + Eigen::Vector3d(d->Uniform(0.10, 0.25), 0.0, 0.0), d, s);
  return true;
}

// What the suite needs of the setup: the graph's hand-over and fetch_left,
// the person's reach into the tray and assembly, the usable recordings.
SharedSpaceCell MakeSharedSpaceCell(const BenchmarkSetup& setup) {
  SharedSpaceCell c;
  c.setup = &setup;
  c.planner = setup.models.planner;
  c.poses = GraphPoses(setup.tasks);
  for (const auto& t : setup.tasks) {
    if (t.name == "hand_over") c.hand_over = &t;
    if (t.name == "fetch_left") c.fetch_left = &t;
  }
  if (!c.hand_over || !c.fetch_left) {
    throw std::invalid_argument("the shared-space suite needs the task graph's 'hand_over' and 'fetch_left' tasks");
  }
  for (const auto& a : setup.person.actions) {
    if (a.name == "reach_parts" && a.kind == perception::MotionKind::kReach) c.reach_parts = &a;
    if (a.name == "assemble" && a.kind == perception::MotionKind::kWork) c.assemble = &a;
    if (a.kind == perception::MotionKind::kRest && !c.rest_is_cells) {
      c.rest = a;
      c.rest_is_cells = true;
    }
  }
  if (!c.reach_parts || !c.assemble) {
    throw std::invalid_argument(
        "the shared-space suite needs the synthetic person's 'reach_parts' (motion reach) and 'assemble' (motion work) "
        "actions");
  }
  if (!c.rest_is_cells) {
    c.rest.name = "idle";
    c.rest.kind = perception::MotionKind::kRest;
    c.rest.period = 3.0;
    c.rest.amplitude = 0.02;
  }
  for (const auto& s : setup.person.script) c.script += (c.script.empty() ? "" : ",") + s.action;
  if (c.script.empty()) c.script = setup.person.actions.front().name;
  const auto home_it = std::find_if(c.poses.begin(), c.poses.end(), [](const NamedPose& p) { return p.name == "home"; });
  c.home = home_it != c.poses.end() ? home_it->q : c.poses.front().q;
  c.R_home = EndEffectorPose(*c.planner, c.home).linear();
  for (const auto& s : setup.recordings->sequences) {
    if (!Usable(*setup.recordings, s)) continue;
    if (!c.by_subject.count(s.subject)) c.subjects.push_back(s.subject);
    c.by_subject[s.subject].push_back(&s);
  }
  if (c.subjects.empty()) throw std::invalid_argument(setup.recordings_file + ": no sequence shows every joint");
  return c;
}

}  // namespace

std::vector<ScenarioSpec> MakeSharedSpaceScenarios(const BenchmarkSetup& setup, int count, uint64_t seed) {
  if (const std::string why = setup.shared_space.Validate(); !why.empty()) {
    throw std::invalid_argument("shared-space suite: " + why);
  }
  const SharedSpaceCell c = MakeSharedSpaceCell(setup);
  const int kinds = static_cast<int>(SharedSpaceKinds().size());
  const double limit = setup.shared_space.max_path_distance;
  std::vector<ScenarioSpec> out;
  for (int i = 0; i < count; ++i) {
    const int kind = i % kinds;
    const bool synthetic = (i / kinds) % 2 == 0;
    // Recorded scenarios (the second block of four in every eight) take the
    // subjects in turn, shifted by one every eight so that with two subjects
    // each kind gets both.
    const int recorded = (i / (2 * kinds)) * (kinds + 1) + kind;
    Draws d(Mix(seed) ^ Mix(0x5ba4e0000ULL + static_cast<uint64_t>(i)));
    const uint64_t noise_seed = d.Next();
    double nearest = std::numeric_limits<double>::infinity();
    bool kept = false;
    for (int draw = 1; draw <= setup.shared_space.max_draws && !kept; ++draw) {
      ScenarioSpec s;
      s.index = i;
      s.seed = noise_seed;
      s.kind = SharedSpaceKinds()[static_cast<std::size_t>(kind)];
      s.draws = draw;
      if (!DrawShared(c, kind, synthetic, recorded, &d, &s)) continue;
      const double distance = ScenarioPathDistance(setup, s);
      nearest = std::min(nearest, distance);
      if (!(distance < limit)) continue;
      s.path_distance = distance;
      out.push_back(std::move(s));
      kept = true;
    }
    if (!kept) {
      throw std::runtime_error("shared-space scenario " + std::to_string(i) + " (" +
                               SharedSpaceKinds()[static_cast<std::size_t>(kind)] + "): no draw of " +
                               std::to_string(setup.shared_space.max_draws) + " brought the person within " +
                               std::to_string(limit) + " m of the robot's path (nearest " + std::to_string(nearest) +
                               " m)");
    }
  }
  return out;
}


}  // namespace internal

using namespace internal;

const std::vector<std::string>& SharedSpaceKinds() {
  static const std::vector<std::string> kKinds = {"hand-over", "parts-bin", "co-assembly", "crossing"};
  return kKinds;
}

std::string SharedSpaceParams::Validate() const {
  if (!(max_path_distance > 0) || !std::isfinite(max_path_distance)) {
    return "max_path_distance must be > 0 m, got " + std::to_string(max_path_distance);
  }
  if (!(window > 0) || !std::isfinite(window)) return "window must be > 0 s, got " + std::to_string(window);
  if (path_samples < 2) return "path_samples must be >= 2, got " + std::to_string(path_samples);
  if (max_draws < 1) return "max_draws must be >= 1, got " + std::to_string(max_draws);
  return "";
}

double PathDistance(const collision::RobotModel& robot, const collision::HumanBodyModel& body,
                    const Eigen::VectorXd& start_q, const Eigen::VectorXd& goal_q, int samples,
                    const PersonStream& person, double t0, double t1) {
  if (start_q.size() != robot.nq || goal_q.size() != robot.nq) {
    throw std::invalid_argument("PathDistance: start and goal need " + std::to_string(robot.nq) + " joint positions");
  }
  if (samples < 2) throw std::invalid_argument("PathDistance: samples must be >= 2, got " + std::to_string(samples));
  if (person.joint_names != body.params().joints) {
    throw std::invalid_argument("PathDistance: the person's joints are not the body model's, in its order");
  }
  if (!(t1 >= t0)) throw std::invalid_argument("PathDistance: the window ends before it starts");
  // The robot's spheres along the path, once.
  collision::RobotData data(robot);
  const std::size_t K = robot.spheres.size();
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(static_cast<std::size_t>(samples) * K);
  for (int k = 0; k < samples; ++k) {
    const double u = static_cast<double>(k) / (samples - 1);
    collision::CalcForwardKinematics(robot, start_q + u * (goal_q - start_q), &data);
    for (std::size_t j = 0; j < K; ++j) centres.push_back(data.p_WS.col(static_cast<Eigen::Index>(j)));
  }
  double best = std::numeric_limits<double>::infinity();
  int frames = 0;
  for (int f = 0; f < person.num_frames(); ++f) {
    if (person.stamp(f) < t0 || person.stamp(f) > t1) continue;
    ++frames;
    const Eigen::Matrix3Xd& joints = person.truth[static_cast<std::size_t>(f)];
    for (int h = 0; h < body.num_spheres(); ++h) {
      const Eigen::Vector3d c = body.SphereCentre(h, joints);
      const double r = body.spheres()[static_cast<std::size_t>(h)].radius;
      for (std::size_t i = 0; i < centres.size(); ++i) {
        best = std::min(best, (centres[i] - c).norm() - robot.spheres[i % K].radius - r);
      }
    }
  }
  if (frames == 0) throw std::invalid_argument("PathDistance: no frame of the person in the window");
  return best;
}

double ScenarioPathDistance(const BenchmarkSetup& setup, const ScenarioSpec& spec) {
  const double t0 = setup.loop.task_start, t1 = t0 + setup.shared_space.window;
  const PersonStream person = MakePersonStream(setup, spec, t1 + 0.1);
  return PathDistance(setup.models.planner->robot(), *setup.models.body, spec.start_q, spec.goal_q,
                      setup.shared_space.path_samples, person, t0, t1);
}

}  // namespace iplan::cell_sim
