// Benchmarks of the collision bound (Release, one thread). Plain executable:
// prints medians and spread (min, max) over repetitions.
//
//  1. Pair bounds per second, Newton (secular equation) and the reference
//     bisection in the same run, on the same cases. As in batched use, each
//     human sphere's covariance is factorised once (per time step) and then
//     evaluated against all robot spheres of the waypoint(s) at that step; the
//     factorisation time is included.
//  2. A 30-waypoint Panda trajectory against a 10-action, 15-step, 16-sphere
//     prediction: the batched evaluation alone (prediction factorised once, as
//     in the optimiser's inner loop) and including forward kinematics and the
//     factorisation of the whole prediction.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "iplan/collision/bound.h"
#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/trajectory_bound.h"
#include "bench_timing.h"

namespace iplan::collision {
namespace {

struct HumanCase {
  Eigen::Vector3d mu;
  Eigen::Matrix3d sigma;
};

Eigen::Matrix3d RandomRotation(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  Eigen::Quaterniond q(n01(*rng), n01(*rng), n01(*rng), n01(*rng));
  return q.normalized().toRotationMatrix();
}

// 2000 human Gaussians x 36 robot spheres spread over the workspace around
// the person: ~0.05 .. 1 m away, so most pairs need the secular solve.
struct PairCases {
  static constexpr int kHuman = 2000;  // human spheres (one factorisation each)
  static constexpr int kRobot = 36;    // robot spheres per waypoint (Panda YAML model)
  std::vector<HumanCase> humans;
  std::vector<Eigen::Vector3d> robot;
  std::vector<double> radius;      // robot + human radius per pair
  std::vector<double> log_volume;  // log V(radius) per pair
  int inside = 0;                  // pairs with the mean inside the ball
  double pairs() const { return static_cast<double>(kHuman) * kRobot; }
};

PairCases MakePairCases() {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01;
  PairCases c;
  c.humans.resize(PairCases::kHuman);
  c.robot.resize(static_cast<size_t>(PairCases::kHuman) * PairCases::kRobot);
  c.radius.resize(c.robot.size());
  for (int h = 0; h < PairCases::kHuman; ++h) {
    const double s_max = std::pow(0.02 + 0.15 * u01(rng), 2);
    const double ratio = std::pow(10.0, 3.0 * u01(rng));
    const Eigen::Matrix3d V = RandomRotation(&rng);
    c.humans[h].sigma = V * Eigen::Vector3d(s_max / ratio, s_max / std::pow(ratio, u01(rng)), s_max)
                                .asDiagonal() * V.transpose();
    c.humans[h].sigma = (0.5 * (c.humans[h].sigma + c.humans[h].sigma.transpose())).eval();
    c.humans[h].mu = Eigen::Vector3d(0.7, 0.0, 0.8) + 0.2 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    for (int k = 0; k < PairCases::kRobot; ++k) {
      const size_t i = static_cast<size_t>(h) * PairCases::kRobot + k;
      c.radius[i] = 0.06 + 0.04 * u01(rng) + 0.08;  // robot + human radius
      const Eigen::Vector3d dir = Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
      c.robot[i] = c.humans[h].mu + (0.05 + 0.95 * u01(rng)) * dir;
      if ((c.robot[i] - c.humans[h].mu).norm() <= c.radius[i]) ++c.inside;
    }
  }
  c.log_volume.resize(c.radius.size());
  for (size_t i = 0; i < c.radius.size(); ++i) c.log_volume[i] = std::log(BallVolume(c.radius[i]));
  return c;
}

// Accuracy on this set: Newton vs the bisection at the benchmarked tolerance.
void PrintPairAccuracy(const PairCases& c, const ReferenceBisectionOptions& bis) {
  double max_rel = 0.0, max_rel_x = 0.0;
  double iter_newton = 0.0, iter_bis = 0.0;
  int outside = 0;
  for (int h = 0; h < PairCases::kHuman; ++h) {
    FactorizedGaussian g;
    FactorizeGaussian(c.humans[h].mu, c.humans[h].sigma, &g);
    for (int k = 0; k < PairCases::kRobot; ++k) {
      const size_t i = static_cast<size_t>(h) * PairCases::kRobot + k;
      const PairBound a = EvaluatePairBound(g, c.robot[i], c.radius[i]);
      const PairBound b = EvaluatePairBoundReferenceBisection(g, c.robot[i], c.radius[i], bis);
      if (a.bound > 1e-300) max_rel = std::max(max_rel, std::abs(a.bound - b.bound) / a.bound);
      max_rel_x = std::max(max_rel_x, (a.x_max - b.x_max).norm() / c.radius[i]);
      if (a.lambda > 0) {
        ++outside;
        iter_newton += a.iterations;
        iter_bis += b.iterations;
      }
    }
  }
  std::printf("== Pair bounds (%d human spheres x %d robot spheres = %.0f pairs per batch;\n"
              "   one covariance factorisation per human sphere included; %.1f %% of pairs\n"
              "   have the mean inside the ball)\n",
              PairCases::kHuman, PairCases::kRobot, c.pairs(), 100.0 * c.inside / c.pairs());
  std::printf("   accuracy: max |bound_newton - bound_bisection| / bound = %.2e, "
              "max ||x_newton - x_bisection|| / R = %.2e\n", max_rel, max_rel_x);
  std::printf("   mean iterations on pairs outside the ball: Newton %.2f, bisection %.1f "
              "(bisection relative tolerance %.0e)\n",
              iter_newton / outside, iter_bis / outside, bis.relative_tolerance);
}

// The ways of evaluating every pair that the benchmark times.
enum class PairMethod { kBound, kLogBound, kBatched, kBatchedLogVolume, kBisection };

double RunPairs(const PairCases& c, PairMethod method, const ReferenceBisectionOptions& bis) {
  double s = 0.0;
  FactorizedGaussian g;
  double out[PairCases::kRobot];
  Eigen::Map<const Eigen::Matrix3Xd> all(c.robot[0].data(), 3, static_cast<Eigen::Index>(c.robot.size()));
  for (int h = 0; h < PairCases::kHuman; ++h) {
    FactorizeGaussian(c.humans[h].mu, c.humans[h].sigma, &g);
    const size_t base = static_cast<size_t>(h) * PairCases::kRobot;
    switch (method) {
      case PairMethod::kBound:
        for (int k = 0; k < PairCases::kRobot; ++k) s += EvaluatePairBound(g, c.robot[base + k], c.radius[base + k]).bound;
        break;
      case PairMethod::kLogBound:
        for (int k = 0; k < PairCases::kRobot; ++k) s += EvaluatePairLogBound(g, c.robot[base + k], c.radius[base + k]);
        break;
      case PairMethod::kBatched:
      case PairMethod::kBatchedLogVolume:
        EvaluatePairLogBounds(g, all.middleCols(static_cast<Eigen::Index>(base), PairCases::kRobot), &c.radius[base], out,
                              method == PairMethod::kBatchedLogVolume ? &c.log_volume[base] : nullptr);
        for (int k = 0; k < PairCases::kRobot; ++k) s += out[k];
        break;
      case PairMethod::kBisection:
        for (int k = 0; k < PairCases::kRobot; ++k)
          s += EvaluatePairBoundReferenceBisection(g, c.robot[base + k], c.radius[base + k], bis).bound;
        break;
    }
  }
  return s;
}

void PairBenchmark() {
  const PairCases c = MakePairCases();
  ReferenceBisectionOptions bis;
  bis.relative_tolerance = 1e-12;
  PrintPairAccuracy(c, bis);
  volatile double sink = 0.0;
  auto timed = [&](PairMethod m, int reps, double min_seconds, double* wall) {
    const Stats s = Measure([&] { sink = sink + RunPairs(c, m, bis); }, c.pairs(), reps, min_seconds);
    *wall = g_last_wall_median;
    return s;
  };
  constexpr int kReps = 11;
  double newton_wall, newton_log_wall, newton_batched_wall, newton_batched_lv_wall, bisection_wall;
  const Stats newton = timed(PairMethod::kBound, kReps, 0.3, &newton_wall);
  const Stats newton_log = timed(PairMethod::kLogBound, kReps, 0.3, &newton_log_wall);
  const Stats newton_batched = timed(PairMethod::kBatched, kReps, 0.3, &newton_batched_wall);
  const Stats newton_batched_lv = timed(PairMethod::kBatchedLogVolume, kReps, 0.3, &newton_batched_lv_wall);
  const Stats bisection = timed(PairMethod::kBisection, 5, 0.5, &bisection_wall);
  const Stats factorise = Measure(
      [&] {
        double s = 0.0;
        FactorizedGaussian g;
        for (int h = 0; h < PairCases::kHuman; ++h) {
          FactorizeGaussian(c.humans[h].mu, c.humans[h].sigma, &g);
          s += g.log_peak_density;
        }
        sink = sink + s;
      },
      PairCases::kHuman, kReps, 0.2);

  std::printf("   (thread CPU time; rate = pairs / CPU second; wall-clock median in brackets)\n");
  auto line = [](const char* name, const Stats& s, double wall) {
    std::printf("   %-40s median %6.2f M/s  (min %.2f, max %.2f; %.1f ns/pair) [wall %.2f M/s]\n",
                name, 1e-6 / s.median, 1e-6 / s.max, 1e-6 / s.min, 1e9 * s.median, 1e-6 / wall);
  };
  line("Newton, EvaluatePairBound (+x_max)", newton, newton_wall);
  line("Newton, EvaluatePairLogBound", newton_log, newton_log_wall);
  line("Newton, EvaluatePairLogBounds (2 lanes)", newton_batched, newton_batched_wall);
  line("Newton, ...Bounds + precomputed log V(R)", newton_batched_lv, newton_batched_lv_wall);
  line("reference bisection", bisection, bisection_wall);
  std::printf("   speed-up over bisection (medians): EvaluatePairBound %.1fx, log path %.1fx, "
              "batched %.1fx, batched with log V %.1fx\n",
              bisection.median / newton.median, bisection.median / newton_log.median,
              bisection.median / newton_batched.median, bisection.median / newton_batched_lv.median);
  std::printf("   covariance factorisation alone: median %.1f ns (min %.1f, max %.1f)\n",
              1e9 * factorise.median, 1e9 * factorise.min, 1e9 * factorise.max);
}

// A person standing `distance` in front of the robot; each action moves the
// right hand towards a different point (into the arm's path with
// reach_into_path), uncertainty growing with time. The arm swings from one
// side to the other in front of it.
class TrajectoryCase {
 public:
  static constexpr int kActions = 10, kSteps = 15, kWaypoints = 30;
  static constexpr double kDt = 0.1;  // s between prediction steps

  TrajectoryCase(double distance, bool reach_into_path)
      : robot(LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml")),
        body(HumanBodyParams::DefaultUpperBody()),
        prediction(body.MakePrediction(kActions, kSteps)),
        pelvis_(distance, 0.0, 0.0),
        reach_into_path_(reach_into_path),
        data_(robot) {
    Eigen::VectorXd q0(7), q1(7);
    q0 << -1.2, 0.3, 0.0, -1.8, 0.0, 2.0, 0.8;
    q1 << 1.2, 0.5, 0.0, -1.5, 0.0, 2.0, 0.8;
    for (int w = 0; w < kWaypoints; ++w) qs_.push_back(q0 + (q1 - q0) * (static_cast<double>(w) / (kWaypoints - 1)));
    for (const CollisionSphere& sp : robot.spheres) {
      traj.radii.push_back(sp.radius);
      traj.links.push_back(sp.link);
    }
    traj.centres.resize(3, static_cast<Eigen::Index>(kWaypoints) * num_robot_spheres());
    traj.steps.resize(kWaypoints);
    FillPrediction();
    FillTrajectory();
  }

  int num_robot_spheres() const { return static_cast<int>(robot.spheres.size()); }

  void FillPrediction() {
    const std::vector<Eigen::Vector3d> rest = {
        {0.0, 0.0, 1.65}, {0.0, 0.0, 1.45}, {0.0, 0.0, 1.05},   {0.0, 0.2, 1.40}, {0.0, 0.25, 1.12},
        {0.0, 0.27, 0.85}, {0.0, -0.2, 1.40}, {0.0, -0.25, 1.12}, {0.0, -0.27, 0.85}};
    Eigen::Matrix3Xd means(3, 9);
    std::vector<Eigen::Matrix3d> covs(9);
    for (int c = 0; c < kActions; ++c) {
      prediction.set_action_probability(c, (c + 1.0) / (kActions * (kActions + 1) / 2.0));
      const double angle = 3.14159265358979 * (0.5 + c / (kActions - 1.0));
      const Eigen::Vector3d target =
          reach_into_path_ ? Eigen::Vector3d(0.35 + 0.1 * std::cos(angle), 0.4 * std::sin(angle), 0.55)
                           : Eigen::Vector3d(pelvis_ + Eigen::Vector3d(0.5 * std::cos(angle), 0.5 * std::sin(angle), 0.9));
      for (int t = 0; t < kSteps; ++t) {
        const double s = static_cast<double>(t) / (kSteps - 1);
        for (int j = 0; j < 9; ++j) {
          means.col(j) = pelvis_ + rest[j];
          const double sd = 0.02 + 0.01 * t * kDt * 10.0 / kSteps * (j >= 6 ? 3.0 : 1.0);
          // Anisotropic: more uncertainty horizontally than vertically.
          covs[j] = Eigen::Vector3d(sd * sd, sd * sd, 0.25 * sd * sd).asDiagonal();
        }
        means.col(8) = (1 - s) * means.col(8) + s * target;
        means.col(7) = (1 - 0.5 * s) * means.col(7) + 0.5 * s * target;
        body.FillPrediction(means, covs, c, t, &prediction);
      }
    }
    prediction.UpdateSummaries();
  }

  void FillTrajectory() {
    const int S = num_robot_spheres();
    for (int w = 0; w < kWaypoints; ++w) {
      CalcForwardKinematics(robot, qs_[w], &data_);
      traj.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = data_.p_WS;
      traj.steps[w] = (w * kSteps) / kWaypoints;
    }
  }

  // Every pair without pruning (the reference).
  double BruteForce() const {
    double s = 0.0;
    const int S = num_robot_spheres();
    for (int w = 0; w < kWaypoints; ++w)
      for (int k = 0; k < S; ++k)
        for (int l = 0; l < body.num_spheres(); ++l)
          s += EvaluateMixtureBound(prediction, traj.steps[w], l, traj.centres.col(static_cast<Eigen::Index>(w) * S + k),
                                    traj.radii[k]);
    return s;
  }

  const RobotModel robot;
  const HumanBodyModel body;
  HumanPrediction prediction;
  RobotSpheresTrajectory traj;

 private:
  const Eigen::Vector3d pelvis_;
  const bool reach_into_path_;
  std::vector<Eigen::VectorXd> qs_;
  RobotData data_;
};

void TrajectoryBenchmark(double distance, bool reach_into_path, const char* scenario) {
  TrajectoryCase c(distance, reach_into_path);
  const int S = c.num_robot_spheres();
  constexpr int kWaypoints = TrajectoryCase::kWaypoints;
  TrajectoryBoundWorkspace ws(S, c.body.num_spheres());
  std::vector<WaypointBound> out(kWaypoints);
  TrajectoryBoundParams params;
  EvaluateTrajectoryBound(c.prediction, c.traj, params, &ws, &out);
  double max_bound = 0.0;
  long evaluated = 0, pruned = 0;
  int argmax_w = 0;
  for (int w = 0; w < kWaypoints; ++w) {
    if (out[w].bound > max_bound) {
      max_bound = out[w].bound;
      argmax_w = w;
    }
    evaluated += out[w].pairs_evaluated;
    pruned += out[w].pairs_pruned;
  }
  volatile double sink = 0.0;
  constexpr int kReps = 21;
  const Stats eval = Measure([&] { EvaluateTrajectoryBound(c.prediction, c.traj, params, &ws, &out); }, 1.0, kReps, 0.2);
  const double eval_wall = g_last_wall_median;
  const Stats full = Measure(
      [&] {
        c.FillTrajectory();
        c.FillPrediction();
        EvaluateTrajectoryBound(c.prediction, c.traj, params, &ws, &out);
      },
      1.0, kReps, 0.2);
  const double full_wall = g_last_wall_median;
  const Stats unpruned = Measure([&] { sink = sink + c.BruteForce(); }, 1.0, 5, 0.3);
  const double unpruned_wall = g_last_wall_median;

  std::printf("\n== Trajectory bound, %s: Panda (%d spheres) x %d waypoints vs %d actions x "
              "%d steps x %d human spheres\n",
              scenario, S, kWaypoints, TrajectoryCase::kActions, TrajectoryCase::kSteps, c.body.num_spheres());
  std::printf("   workload: %d pair checks, %ld evaluated exactly (x %d actions), %ld pruned; "
              "max bound %.3e at waypoint %d\n",
              kWaypoints * S * c.body.num_spheres(), evaluated, TrajectoryCase::kActions, pruned, max_bound, argmax_w);
  std::printf("   (thread CPU time per call; wall-clock median in brackets)\n");
  auto line = [](const char* name, const Stats& s, double wall) {
    std::printf("   %-52s median %7.3f ms  (min %.3f, max %.3f) [wall %.3f ms]\n", name,
                1e3 * s.median, 1e3 * s.min, 1e3 * s.max, 1e3 * wall);
  };
  line("EvaluateTrajectoryBound (prediction prepared)", eval, eval_wall);
  line("FK 30 waypoints + factorise 2400 Gaussians + evaluate", full, full_wall);
  line("unpruned brute force (reference)", unpruned, unpruned_wall);
}

}  // namespace
}  // namespace iplan::collision

namespace iplan::collision {
void PointsBenchmark();  // points_bench.cc
}  // namespace iplan::collision

int main() {
  std::printf("iplan collision benchmarks (single thread)\n\n");
  iplan::collision::PairBenchmark();
  iplan::collision::TrajectoryBenchmark(0.75, false, "person 0.75 m in front of the base");
  iplan::collision::TrajectoryBenchmark(0.6, true, "person 0.6 m away, hand reaching into the path");
  iplan::collision::PointsBenchmark();
  return 0;
}
