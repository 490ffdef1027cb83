// The bound against a person seen as depth points (point_bound.h), per
// executing trajectory: the Panda reaching out over 15 waypoints (1.5 s at
// 0.1 s, as the collision-risk monitor checks it) against the camera-facing
// half of a standing person (a half cylinder of radius 0.15 m, 1.5 m tall)
// sampled with ~2,000 and ~10,000 points, sensor noise 8 mm along the
// camera's axis and 3 mm across. Two placements: the person just beyond the
// arm's reach, and in its path. Thread CPU time per call, median (min, max)
// over repetitions; the culled evaluation beside the all-pairs reference.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_timing.h"
#include "iplan/collision/point_bound.h"
#include "iplan/collision/robot_model.h"

namespace iplan::collision {
namespace {

GaussianPoints MakePerson(double x, int around, int up, Eigen::Matrix3Xd* means, std::vector<Eigen::Matrix3d>* covs) {
  means->resize(3, around * up);
  covs->assign(static_cast<std::size_t>(around * up), Eigen::Vector3d(6.4e-5, 9e-6, 9e-6).asDiagonal());
  for (int a = 0; a < around; ++a) {
    const double phi = M_PI / 2 + M_PI * (a + 0.5) / around;
    for (int h = 0; h < up; ++h)
      means->col(a * up + h) = Eigen::Vector3d(x + 0.15 * std::cos(phi), 0.15 * std::sin(phi), 0.2 + 1.5 * h / up);
  }
  GaussianPoints pts;
  pts.Set(*means, *covs, 0.005);
  return pts;
}

RobotSpheresTrajectory Reaching(const RobotModel& robot) {
  const Eigen::VectorXd ready = (Eigen::VectorXd(7) << 0, -0.785, 0, -2.356, 0, 1.571, 0.785).finished();
  const Eigen::VectorXd reach = (Eigen::VectorXd(7) << 0, 0.3, 0, -1.5, 0, 1.9, 0.785).finished();
  RobotSpheresTrajectory t;
  for (const auto& s : robot.spheres) {
    t.radii.push_back(s.radius);
    t.links.push_back(s.link);
  }
  const int S = t.num_spheres(), W = 15;
  t.centres.resize(3, W * S);
  RobotData d(robot);
  for (int w = 0; w < W; ++w) {
    const double u = 0.5 - 0.5 * std::cos(M_PI * (w + 1) / W);
    CalcForwardKinematics(robot, (1 - u) * ready + u * reach, &d);
    t.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = d.p_WS;
    t.steps.push_back(w);
  }
  return t;
}

void Line(const char* name, const Stats& s, double wall) {
  std::printf("   %-44s median %8.3f ms  (min %.3f, max %.3f) [wall %.3f ms]\n", name, 1e3 * s.median, 1e3 * s.min,
              1e3 * s.max, 1e3 * wall);
}

void PointsCase(const RobotModel& robot, const RobotSpheresTrajectory& t, double x, int around, int up,
                const char* where) {
  Eigen::Matrix3Xd means;
  std::vector<Eigen::Matrix3d> covs;
  GaussianPoints pts = MakePerson(x, around, up, &means, &covs);
  std::vector<WaypointBound> out, all;
  EvaluatePointsBound(pts, t, PointsBoundParams{}, &out);
  EvaluatePointsBoundAllPairs(pts, t, &all);
  long evaluated = 0, culled = 0;
  double max_bound = 0, max_all = 0;
  for (std::size_t w = 0; w < out.size(); ++w) {
    evaluated += out[w].pairs_evaluated;
    culled += out[w].pairs_pruned;
    max_bound = std::max(max_bound, out[w].bound);
    max_all = std::max(max_all, all[w].bound);
  }
  std::printf("\n== Points bound, %d points (%d blocks), person %s: Panda (%d spheres) x %d waypoints\n", pts.size(),
              static_cast<int>(pts.blocks().size()), where, t.num_spheres(), t.num_waypoints());
  std::printf("   workload: %ld pairs, %ld evaluated, %ld culled; max bound %.3e (all pairs %.3e)\n",
              static_cast<long>(pts.size()) * t.num_spheres() * t.num_waypoints(), evaluated, culled, max_bound, max_all);
  const Stats eval = Measure([&] { EvaluatePointsBound(pts, t, PointsBoundParams{}, &out); }, 1.0, 21, 0.2);
  Line("EvaluatePointsBound (points prepared)", eval, g_last_wall_median);
  const Stats set = Measure([&] { pts.Set(means, covs, 0.005); }, 1.0, 11, 0.2);
  Line("GaussianPoints::Set (factorise, blocks)", set, g_last_wall_median);
  const Stats ref = Measure([&] { EvaluatePointsBoundAllPairs(pts, t, &all); }, 1.0, 3, 0.2);
  Line("all pairs, no culling (reference)", ref, g_last_wall_median);
}

}  // namespace

void PointsBenchmark() {
  const RobotModel robot = LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
  const RobotSpheresTrajectory t = Reaching(robot);
  for (const auto& [around, up] : {std::pair{25, 80}, std::pair{56, 180}}) {
    PointsCase(robot, t, 0.95, around, up, "0.06 m beyond the arm's reach");
    PointsCase(robot, t, 0.80, around, up, "in the arm's path");
  }
}

}  // namespace iplan::collision
