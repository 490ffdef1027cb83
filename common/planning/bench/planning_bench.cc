// Planning benchmark (plain executable; figures printed, no assertions).
//
// 1. One-shot: >= 50 seeded table-top problems for the Panda in
//    config/scenes/cell.yaml: start at the IK solution of one named pose
//    (table, shelf height, above the bin; +-3 cm jitter), goal another pose
//    (pose goal for even problems, joint goal for odd ones). Success within
//    1 s, time to first feasible trajectory, final cost, for 8 optimisers and
//    for 1 optimiser (multi-start gain).
// 2. Replanning: a synthesised person (default 16-sphere upper body) standing
//    across the table walks along it (torso y from -0.5 to +0.5 m over the
//    run) while the prediction mixture has 10 reaching actions (hand to
//    x = 0.78-0.84 m, y = -0.45..0.45 m, the person's half of the table) x 15 steps
//    (0.1 s). Every cycle (m = 0.1 s) the previous trajectory is shifted by
//    0.1 s and warm-starts the planner with the first 3 waypoints frozen.
//    The cycle time is the wall time of Planner::Plan.
#include <functional>
#include <map>
#include <stdexcept>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "../test/test_util.h"
#include "iplan/intent/skeleton_data.h"
#include "iplan/collision/human_model.h"
#include "iplan/cell/joint_trajectory.h"
#include "iplan/collision/static_scene.h"
#ifdef IPLAN_HAVE_OMPL
#include "ompl_peer.h"
#endif
#include "iplan/planning/planner.h"
#include "iplan/core/checksum.h"

using namespace iplan;
using namespace iplan::planning;

namespace {

double Pct(std::vector<double> v, double p) {
  if (v.empty()) return -1.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5));
  return v[i];
}

// FNV-1a over the bytes of a result's trajectory, cost and bounds: a
// fingerprint that changes only when results change (for checking that a
// speed-up is output-preserving).
void Fingerprint(const PlanningResult& r, std::uint64_t* h) {
  auto mix = [h](const void* p, std::size_t n) { *h = core::Fnv1a64(p, n, *h); };
  mix(r.positions.data(), sizeof(double) * r.positions.size());
  mix(&r.cost, sizeof r.cost);
  mix(r.bounds.data(), sizeof(double) * r.bounds.size());
  mix(&r.num_waits, sizeof r.num_waits);
}

struct Problem {
  Eigen::VectorXd start;
  Goal goal;
  std::string name;
};



// Recorded arm motion at 10 Hz in the cell frame (W): shoulders, elbows and
// wrists from the file, neck/head/torso derived from the shoulders.
struct RecordedPerson {
  std::vector<std::map<std::string, Eigen::Vector3d>> frames;  // at 0.1 s
};

RecordedPerson LoadRecordedPerson(const std::string& csv, const std::string& sequence) {
  const intent::SkeletonDataset data = intent::LoadSkeletonCsv(csv);
  const intent::SkeletonSequence* seq = nullptr;
  for (const auto& s : data.sequences) {
    if (s.id == sequence) seq = &s;
  }
  if (!seq) throw std::runtime_error(csv + ": no sequence " + sequence);
  auto col = [&](const std::string& name) {
    for (std::size_t j = 0; j < data.joint_names.size(); ++j) {
      if (data.joint_names[j] == name) return static_cast<int>(j);
    }
    throw std::runtime_error(csv + ": no joint " + name);
  };
  const std::pair<const char*, const char*> map[] = {{"shoulder_l", "shoulder_l"}, {"elbow_l", "elbow_l"},
                                                     {"hand_l", "wrist_l"},         {"shoulder_r", "shoulder_r"},
                                                     {"elbow_r", "elbow_r"},        {"hand_r", "wrist_r"}};
  // Sensor frame (optical: x right, y down, z away from the camera, which
  // faces the person from the robot's side) to the cell: z -> +x, x -> -y,
  // y -> -z; the mean shoulder centre goes to (1.05, 0, 0.5) m.
  Eigen::Matrix3d R_WS;
  R_WS << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Vector3d centre_S = Eigen::Vector3d::Zero();
  int n = 0;
  std::map<std::string, Eigen::Vector3d> last;
  RecordedPerson out;
  std::vector<std::map<std::string, Eigen::Vector3d>> raw;
  for (double t = 0; t <= seq->time[seq->time.size() - 1]; t += 0.1) {
    Eigen::Index i = 0;
    while (i + 1 < seq->time.size() && seq->time[i + 1] <= t) ++i;
    std::map<std::string, Eigen::Vector3d> f;
    for (const auto& [ours, theirs] : map) {
      const Eigen::Vector3d p = seq->positions.row(i).segment<3>(3 * col(theirs)).transpose();
      if (intent::JointDetected(p.transpose())) last[ours] = p;
      if (last.count(ours)) f[ours] = last[ours];  // undetected: hold the last seen position
    }
    if (f.size() == 6) {
      centre_S += 0.5 * (f["shoulder_l"] + f["shoulder_r"]);
      ++n;
      raw.push_back(f);
    }
  }
  centre_S /= n;
  const Eigen::Vector3d centre_W(1.05, 0.0, 0.5);
  for (auto& f : raw) {
    std::map<std::string, Eigen::Vector3d> w;
    for (auto& [name, p] : f) w[name] = centre_W + R_WS * (p - centre_S);
    const Eigen::Vector3d neck = 0.5 * (w["shoulder_l"] + w["shoulder_r"]);
    w["neck"] = neck;
    w["head"] = neck + Eigen::Vector3d(0, 0, 0.2);
    w["torso"] = neck + Eigen::Vector3d(0, 0, -0.3);
    out.frames.push_back(w);
  }
  return out;
}

// The prediction at cycle k: the recorded future (15 steps of 0.1 s) as the
// most likely action's means, 9 more actions shifted by a few centimetres
// with weights 0.6^c, sigma growing from 3 to 6 cm; the person is moved by
// `y` m sideways.
collision::HumanPrediction RecordedPrediction(const collision::HumanBodyModel& body, const RecordedPerson& person,
                                              int k, double y) {
  const int na = 10, steps = 15;
  collision::HumanPrediction pred = body.MakePrediction(na, steps);
  double wsum = 0;
  for (int c = 0; c < na; ++c) wsum += std::pow(0.6, c);
  Eigen::Matrix3Xd means(3, body.num_joints());
  std::vector<Eigen::Matrix3d> covs(static_cast<std::size_t>(body.num_joints()));
  for (int c = 0; c < na; ++c) {
    pred.set_action_probability(c, std::pow(0.6, c) / wsum);
    const Eigen::Vector3d shift(-0.02 * (c % 3), 0.03 * ((c % 5) - 2), 0.02 * (c % 2));
    for (int s = 0; s < steps; ++s) {
      const auto& f = person.frames[std::min(person.frames.size() - 1, static_cast<std::size_t>(k + s + 1))];
      const double sigma = 0.03 + 0.03 * s / (steps - 1);
      for (int j = 0; j < body.num_joints(); ++j) {
        means.col(j) = f.at(body.params().joints[static_cast<std::size_t>(j)]) + shift + Eigen::Vector3d(0, y, 0);
        covs[static_cast<std::size_t>(j)] = sigma * sigma * Eigen::Matrix3d::Identity();
      }
      body.FillPrediction(means, covs, c, s, &pred);
    }
  }
  pred.UpdateSummaries();
  return pred;
}

// Seeded table-top problems: start and goal from the named poses, +-3 cm
// and +-0.3 rad yaw jitter; every other goal a pose, the others joints.
// `ready` seeds the first IK of each problem.
std::vector<Problem> MakeProblems(const Planner& planner, const Eigen::VectorXd& ready, int num_problems,
                                  int* ik_rejected) {
  const auto poses = testing::TableTopPoses();
  std::mt19937_64 rng(2026);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(poses.size()) - 1);
  std::uniform_real_distribution<double> jit(-0.03, 0.03), yaw(-0.3, 0.3);
  std::vector<Problem> problems;
  *ik_rejected = 0;
  while (static_cast<int>(problems.size()) < num_problems) {
    if (*ik_rejected > 100 * num_problems) {
      std::fprintf(stderr, "planning_bench: %d candidate poses rejected (no IK or start in collision) for %zu "
                           "problems; this robot does not reach the cell's table-top poses\n",
                   *ik_rejected, problems.size());
      std::exit(1);
    }
    const int a = pick(rng), b = pick(rng);
    if (a == b) continue;
    const Eigen::Vector3d pa = poses[a].p + Eigen::Vector3d(jit(rng), jit(rng), jit(rng));
    const Eigen::Vector3d pb = poses[b].p + Eigen::Vector3d(jit(rng), jit(rng), jit(rng));
    const double ya = yaw(rng), yb = yaw(rng);
    const IkResult s = planner.SolveIk(pa, testing::DownOrientation(ya), ready, problems.size());
    if (!s.success || planner.CalcClearance(s.q) < 0.0) {
      ++*ik_rejected;
      continue;
    }
    Problem pr;
    pr.start = s.q;
    pr.name = std::string(poses[a].name) + "->" + poses[b].name;
    if (problems.size() % 2 == 0) {
      pr.goal = Goal::Pose(pb, testing::DownOrientation(yb));
    } else {
      const IkResult g = planner.SolveIk(pb, testing::DownOrientation(yb), s.q, problems.size() + 7);
      if (!g.success || planner.CalcClearance(g.q) < 0.0) {
        ++*ik_rejected;
        continue;
      }
      pr.goal = Goal::Joint(g.q);
    }
    problems.push_back(pr);
  }
  return problems;
}

// One-shot planning of every problem with `nopt` optimisers.
void RunOneShot(const Planner& planner, const std::vector<Problem>& problems, int nopt, int threads,
                std::uint64_t* fingerprint) {
  int ok = 0, ok_1s = 0;
  std::vector<double> t_first, t_total, cost;
  for (std::size_t i = 0; i < problems.size(); ++i) {
    PlanningRequest req;
    req.start_q = problems[i].start;
    req.goal = problems[i].goal;
    const PlanningResult r = planner.Plan(req, nopt, std::min(threads, nopt), 1000 + i);
    t_total.push_back(r.planning_time);
    Fingerprint(r, fingerprint);
    if (r.success()) {
      ++ok;
      if (r.planning_time <= 1.0) ++ok_1s;
      t_first.push_back(r.time_to_first_feasible);
      cost.push_back(r.cost);
    } else if (nopt == 8) {
      std::printf("  failed %zu %s: %s (%s)\n", i, problems[i].name.c_str(), ToString(r.status), r.reason.c_str());
    }
  }
  std::printf("one-shot, %d optimiser(s): success %d/%zu = %.1f %%, within 1 s %.1f %% (target >= 95 %%)\n", nopt, ok,
              problems.size(), 100.0 * ok / problems.size(), 100.0 * ok_1s / problems.size());
  std::printf("  time to first feasible: p50 %.1f ms, p99 %.1f ms; planning time p50 %.1f ms, p99 %.1f ms, max %.1f ms\n",
              1e3 * Pct(t_first, 0.5), 1e3 * Pct(t_first, 0.99), 1e3 * Pct(t_total, 0.5), 1e3 * Pct(t_total, 0.99),
              1e3 * Pct(t_total, 1.0));
  std::printf("  final cost: p50 %.2f, p10 %.2f, p90 %.2f\n", Pct(cost, 0.5), Pct(cost, 0.1), Pct(cost, 0.9));
}

// 12 tasks x 25 replanning cycles; `make(k)` is the prediction at cycle k.
// With time_budget > 0 (s per cycle) the results depend on timing and stay
// out of the fingerprint.
void RunReplanning(const Planner& replanner, const std::vector<Problem>& problems, int threads, int num_spheres,
                   const char* label, const std::function<collision::HumanPrediction(int)>& make,
                   std::uint64_t* fingerprint, double time_budget = 0.0) {
  std::vector<double> cycle;
  int tasks = 0, tasks_ok = 0, cycles_failed = 0, total_waits = 0, exhausted = 0, over_step = 0;
  const int cycles_per_task = 25;
  for (std::size_t i = 0; i < problems.size() && tasks < 12; i += 5, ++tasks) {
    PlanningRequest req;
    req.start_q = problems[i].start;
    req.goal = problems[i].goal;
    PlanningResult prev;
    bool task_ok = true;
    for (int k = 0; k < cycles_per_task; ++k) {
      const collision::HumanPrediction pred = make(k);
      req.people = {{&pred, 0.1, 0.0}};
      if (k > 0 && prev.positions.cols() > 1) {
        req.warm_start = Planner::ShiftTrajectory(prev.positions, prev.dt, 0.1);
        req.start_q = req.warm_start.col(0);
        req.start_qdot = (prev.positions.col(2) - prev.positions.col(1)) / prev.dt;
        req.num_frozen = 3;
        req.goal = Goal::Joint(prev.goal_q);
      }
      req.time_budget = time_budget;
      const PlanningResult r = replanner.Plan(req, 8, threads, 77 + k);
      cycle.push_back(r.planning_time);
      exhausted += r.budget_exhausted;
      over_step += r.planning_time > 0.1;
      if (time_budget == 0.0) Fingerprint(r, fingerprint);
      total_waits += r.num_waits;
      if (!r.success()) {
        ++cycles_failed;
        task_ok = false;
        if (r.positions.cols() == 0) break;
      }
      prev = r;
    }
    tasks_ok += task_ok;
  }
  std::printf("replanning, %s (max_waits 1, max_iterations 30, early_stop_interval 3%s): %d tasks x %d cycles, 8 optimisers, %d threads, prediction 10 actions x 15 steps x %d spheres\n",
              label, time_budget > 0 ? (", budget " + std::to_string(static_cast<int>(1e3 * time_budget)) + " ms").c_str() : "",
              tasks, cycles_per_task, threads, num_spheres);
  std::printf("  cycle time p50 %.1f ms, p90 %.1f ms, p99 %.1f ms, max %.1f ms (%s)\n", 1e3 * Pct(cycle, 0.5),
              1e3 * Pct(cycle, 0.9), 1e3 * Pct(cycle, 0.99), 1e3 * Pct(cycle, 1.0),
              time_budget > 0 ? "target p99 <= 60 ms with both cores busy, none over 100 ms" : "target p99 <= 100 ms");
  std::printf("  cycles without a safe trajectory: %d of %zu; waits inserted: %d; tasks with every cycle safe: %d/%d\n",
              cycles_failed, cycle.size(), total_waits, tasks_ok, tasks);
  std::printf("  cycles over the 100 ms step: %d; cycles that ran out of the budget: %d\n", over_step, exhausted);
}

// Static clearance per configuration, the optimiser's analytic distances
// (Planner::CalcClearance: FK + every checked sphere-object pair, with the
// link-ball culling) against FCL (FK + StaticScene::CalcMinimumDistance over
// every pair), on 500 seeded configurations within the joint limits.
void CompareClearance(const Planner& planner, const collision::RobotModel& robot) {
  const collision::StaticScene scene(testing::LoadCell());
  std::mt19937_64 rng(15);
  const Eigen::VectorXd lo = robot.LowerLimits(), hi = robot.UpperLimits();
  std::vector<Eigen::VectorXd> qs;
  for (int i = 0; i < 500; ++i) {
    Eigen::VectorXd q(robot.nq);
    for (int j = 0; j < robot.nq; ++j) q[j] = std::uniform_real_distribution<double>(lo[j], hi[j])(rng);
    qs.push_back(q);
  }
  std::vector<double> radii;
  for (const auto& sp : robot.spheres) radii.push_back(sp.radius);
  collision::RobotData data(robot);
  std::vector<double> analytic, fcl;
  volatile double sink = 0.0;
  for (int rep = 0; rep < 5; ++rep) {
    for (const auto& q : qs) {
      auto t0 = std::chrono::steady_clock::now();
      sink = sink + planner.CalcClearance(q);
      auto t1 = std::chrono::steady_clock::now();
      collision::CalcForwardKinematics(robot, q, &data);
      sink = sink + scene.CalcMinimumDistance(data.p_WS, radii).distance;
      auto t2 = std::chrono::steady_clock::now();
      analytic.push_back(std::chrono::duration<double>(t1 - t0).count());
      fcl.push_back(std::chrono::duration<double>(t2 - t1).count());
    }
  }
  std::printf("static clearance per configuration (%zu spheres x %d objects, FK included, %zu calls): "
              "analytic p50 %.1f us, p99 %.1f us; FCL p50 %.1f us, p99 %.1f us\n",
              radii.size(), scene.num_objects(), analytic.size(), 1e6 * Pct(analytic, 0.5), 1e6 * Pct(analytic, 0.99),
              1e6 * Pct(fcl, 0.5), 1e6 * Pct(fcl, 0.99));
}

#ifdef IPLAN_HAVE_OMPL
// Path figures of a trajectory sampled every dt: joint-space length (rad),
// duration until it stays within 0.01 rad of its end (the replanner's
// goal_tolerance: arrived) (s), and smoothness
// sum_i dt ||a_i||^2 (rad^2/s^3, the optimiser's smoothness term without
// its weight, starting and ending at rest).
struct PathFigures {
  double length = 0, duration = 0, smoothness = 0;
};

PathFigures Figures(const Eigen::MatrixXd& Q, double dt) {
  PathFigures f;
  for (Eigen::Index i = 0; i + 1 < Q.cols(); ++i) f.length += (Q.col(i + 1) - Q.col(i)).norm();
  Eigen::Index last = Q.cols() - 1;
  while (last > 0 && (Q.col(last - 1) - Q.col(Q.cols() - 1)).cwiseAbs().maxCoeff() < 0.01) --last;
  f.duration = static_cast<double>(last) * dt;
  Eigen::MatrixXd A;
  cell::FiniteDifferenceAccelerations(Q, Eigen::VectorXd::Zero(Q.rows()), dt, &A);
  f.smoothness = dt * A.squaredNorm();
  return f;
}

// iplan and OMPL RRTConnect (+ simplification, time parameterisation) on the
// same problems, the same collision model and joint goals (iplan's IK
// solution for the pose goals), within 1 s each.
void ComparePeer(const Planner& planner, const std::vector<Problem>& problems, int threads) {
  struct Row {
    int solved = 0;
    std::vector<double> first, length, duration, smoothness;
    void Add(double t_first, const PathFigures& f) {
      ++solved;
      first.push_back(t_first);
      length.push_back(f.length);
      duration.push_back(f.duration);
      smoothness.push_back(f.smoothness);
    }
  };
  Row ours, ours1, peer;
  const double dt = planner.params().dt;
  for (std::size_t i = 0; i < problems.size(); ++i) {
    PlanningRequest req;
    req.start_q = problems[i].start;
    req.goal = problems[i].goal;
    const PlanningResult r = planner.Plan(req, 8, std::min(threads, 8), 1000 + i);
    const PlanningResult r1 = planner.Plan(req, 1, 1, 1000 + i);
    if (r.success() && r.planning_time <= 1.0) ours.Add(r.time_to_first_feasible, Figures(r.positions, dt));
    if (r1.success() && r1.planning_time <= 1.0) ours1.Add(r1.time_to_first_feasible, Figures(r1.positions, dt));
    if (r.goal_q.size() == 0) continue;
    const bench::PeerResult p = bench::PlanWithRrtConnect(planner, req.start_q, r.goal_q, 1.0, 2026);
    if (p.solved && p.planning_time <= 1.0) peer.Add(p.time_to_solution, Figures(p.positions, dt));
  }
  std::printf("peer comparison on the %zu problems (same robot spheres, scene and min_clearance; joint goals; 1 s each):\n",
              problems.size());
  std::printf("  %-44s %9s %22s %18s %16s %22s\n", "planner", "success", "first solution p50/p99", "length p50 rad",
              "duration p50 s", "smoothness p50 rad2/s3");
  auto line = [&](const char* name, const Row& w) {
    std::printf("  %-44s %4d/%-4zu %9.1f / %6.1f ms %18.2f %16.1f %22.2f\n", name, w.solved, problems.size(),
                1e3 * Pct(w.first, 0.5), 1e3 * Pct(w.first, 0.99), Pct(w.length, 0.5), Pct(w.duration, 0.5),
                Pct(w.smoothness, 0.5));
  };
  line("iplan, 8 optimisers, 2 threads", ours);
  line("iplan, 1 optimiser, 1 thread", ours1);
  line("OMPL RRTConnect + simplifyMax, 1 thread", peer);
}
#endif

// s, the trajectory optimiser's default cycle budget (config/trajopt.yaml).
constexpr double kCycleBudget = 0.05;

// A whole number >= `min` from argv[i], or the default.
int Argument(int argc, char** argv, int i, int fallback, int min) {
  if (argc <= i) return fallback;
  char* end = nullptr;
  const long v = std::strtol(argv[i], &end, 10);
  if (end == argv[i] || *end != '\0' || v < min || v > 100000) {
    std::fprintf(stderr, "usage: planning_bench [problems=60 (>= 1)] [threads=2 (>= 1)] [robot file (default: the "
                         "Panda, config/robots/panda.yaml)]\n");
    std::exit(2);
  }
  return static_cast<int>(v);
}

}  // namespace

// The budgeted replanning cycles with the cell's replanning setting of
// issue 25: the planner predicts the separation monitor (predict_ssm and its
// margins as config/planner_replanning.yaml gives them). Not in the
// fingerprint (which covers the runs without a budget).
template <class Problems, class Recorded>
void RunPredictingTheMonitor(const collision::RobotModel& robot, const Problems& problems, int threads,
                             const PlannerParams& replan_params, const collision::HumanBodyModel& body,
                             const std::vector<Eigen::Vector3d>& targets, const Recorded& recorded) {
  const PlannerParams cell = LoadPlannerParams(std::string(IPLAN_SOURCE_DIR) + "/config/planner_replanning.yaml");
  PlannerParams ssm_params = replan_params;
  ssm_params.predict_ssm = true;
  ssm_params.ssm_margin = cell.ssm_margin;
  ssm_params.ssm_activation = cell.ssm_activation;
  ssm_params.ssm_horizon = cell.ssm_horizon;
  ssm_params.ssm_stop_probability = cell.ssm_stop_probability;
  ssm_params.weights.ssm = cell.weights.ssm;
  Planner ssm_replanner(robot, testing::LoadCell(), ssm_params);
  std::uint64_t ssm_fingerprint = 0;
  RunReplanning(ssm_replanner, problems, threads, body.num_spheres(), "synthesised reaching person, predicting the monitor",
                [&](int k) {
                  const double y = -0.5 + 1.0 * k / 24;
                  return testing::MakeReachingPrediction(body, targets, 15, 0.03, 0.06, Eigen::Vector3d(0.0, y, 0.0));
                },
                &ssm_fingerprint, kCycleBudget);
  RunReplanning(ssm_replanner, problems, threads, body.num_spheres(),
                "recorded person (assembly.csv task1_human1_trial1), predicting the monitor", recorded, &ssm_fingerprint,
                kCycleBudget);
}

int main(int argc, char** argv) {
  const int num_problems = Argument(argc, argv, 1, 60, 1);
  const int threads = Argument(argc, argv, 2, 2, 1);
  // Another arm (a URDF, an overlay or a DH file) in the Panda's place: the
  // planner's config with that robot's links, IK seeded at the middle of
  // its limits (0 for unbounded joints). Not the fingerprinted Panda run.
  const std::string robot_file = argc > 3 ? argv[3] : "";
  const collision::RobotModel robot = robot_file.empty() ? testing::LoadPanda() : collision::LoadRobotModel(robot_file);
  const PlannerParams params =
      AdaptLinksToRobot(LoadPlannerParams(std::string(IPLAN_SOURCE_DIR) + "/config/planner.yaml"), robot);
  Planner planner(robot, testing::LoadCell(), params);
  Eigen::VectorXd ready(robot.nq);
  if (robot_file.empty()) {
    ready << 0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8;
  } else {
    ready = (0.5 * (robot.LowerLimits() + robot.UpperLimits())).unaryExpr([](double v) { return std::isfinite(v) ? v : 0.0; });
  }
  int ik_rejected = 0;
  const std::vector<Problem> problems = MakeProblems(planner, ready, num_problems, &ik_rejected);
  std::printf("planning_bench: %s (%d joints, %zu spheres), %d problems (%d candidate poses rejected: no IK / start "
              "in collision), %d worker threads, dt %.2f s, horizon %.1f s\n",
              robot.name.c_str(), robot.nq, robot.spheres.size(), num_problems, ik_rejected, threads, params.dt,
              params.horizon);
  std::uint64_t fingerprint = 14695981039346656037ULL;
  for (int nopt : {8, 1}) RunOneShot(planner, problems, nopt, threads, &fingerprint);
  CompareClearance(planner, robot);
#ifdef IPLAN_HAVE_OMPL
  ComparePeer(planner, problems, threads);
#else
  std::printf("peer comparison: OMPL not found at build time (Debian libompl-dev; scripts/setup.sh installs it)\n");
#endif

  // Replanning cycles with a moving person.
  const collision::HumanBodyModel body(collision::HumanBodyParams::DefaultUpperBody());
  std::vector<Eigen::Vector3d> targets;
  for (int c = 0; c < 10; ++c) targets.emplace_back(0.78 + 0.03 * (c % 3), -0.45 + 0.1 * c, 0.20 + 0.02 * (c % 4));
  // Replanning configuration: one wait per cycle (the next cycle replans
  // anyway) and fewer iterations, since the warm start is already good; all
  // optimisers stop after the first 3-iteration round in which one of them is
  // feasible and safe (deterministic, see PlannerParams::early_stop_interval).
  PlannerParams replan_params = params;
  replan_params.max_waits = 1;
  replan_params.max_iterations = 30;
  replan_params.early_stop_interval = 3;
  Planner replanner(robot, testing::LoadCell(), replan_params);
  RunReplanning(replanner, problems, threads, body.num_spheres(), "synthesised reaching person",
                [&](int k) {
                  const double y = -0.5 + 1.0 * k / 24;
                  return testing::MakeReachingPrediction(body, targets, 15, 0.03, 0.06, Eigen::Vector3d(0.0, y, 0.0));
                },
                &fingerprint);
  // A recorded person: arm motion of assembly.csv (RealSense + OpenPose,
  // human1, task1 trial1) placed across the table and walking sideways.
  const RecordedPerson person =
      LoadRecordedPerson(std::string(IPLAN_SHARED_DIR) + "/data/assembly.csv", "task1_human1_trial1");
  const auto recorded = [&](int k) { return RecordedPrediction(body, person, k, -0.5 + 1.0 * k / 24); };
  RunReplanning(replanner, problems, threads, body.num_spheres(), "recorded person (assembly.csv task1_human1_trial1)",
                recorded, &fingerprint);
  // The same cycles as the trajectory optimiser runs them, with the cycle
  // budget of config/trajopt.yaml (replanner.cycle_budget): anytime
  // planning, so a loaded machine gets worse plans or a wait, not late ones.
  RunReplanning(replanner, problems, threads, body.num_spheres(), "synthesised reaching person",
                [&](int k) {
                  const double y = -0.5 + 1.0 * k / 24;
                  return testing::MakeReachingPrediction(body, targets, 15, 0.03, 0.06, Eigen::Vector3d(0.0, y, 0.0));
                },
                &fingerprint, kCycleBudget);
  RunReplanning(replanner, problems, threads, body.num_spheres(), "recorded person (assembly.csv task1_human1_trial1)",
                recorded, &fingerprint, kCycleBudget);
  RunPredictingTheMonitor(robot, problems, threads, replan_params, body, targets, recorded);
  std::printf("results fingerprint %016llx (same seeds and results => same value)\n",
              static_cast<unsigned long long>(fingerprint));
  return 0;
}
