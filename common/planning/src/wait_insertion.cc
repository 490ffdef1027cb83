// Wait insertion (METHOD.md section 5): when no optimiser found a safe
// trajectory, the robot holds a safe pose for a while and the optimisers
// run again on the longer trajectory.
#include <algorithm>

#include "iplan/cell/people.h"
#include "planner_model.h"

namespace iplan::planning::internal {

// Holds the last safe pose q_j of the reference candidate (or the end of the
// frozen prefix) for wait_steps waypoints: q_j must be one the robot can
// stop at within its acceleration limits and stay safe at during the wait.
void PlannerModel::InsertWait(Problem* at, const Candidate* ref, int wait_steps) const {
  const double dt = params.dt;
  int j = at->k - 1;
  Eigen::MatrixXd src = at->base;
  if (ref != nullptr) {
    const Candidate& c = *ref;
    src = c.Q;
    int first = c.first_unsafe < 0 ? at->n : c.first_unsafe;
    if (c.ssm.first_violation >= 0) first = std::min(first, c.ssm.first_violation);
    const int start = first - 1;
    Workspace ws;
    for (int cand = start; cand > at->k - 1; --cand) {
      // The robot must be able to stop at q_cand within the acceleration limits.
      const Eigen::VectorXd stop_acc = (c.Q.col(cand - 1) - c.Q.col(cand)) / (dt * dt);
      if ((stop_acc.cwiseAbs().array() > amax.array()).any()) continue;
      // Holding q_cand must stay safe during the wait.
      Problem hold = *at;
      hold.n = cand + wait_steps;
      SetSteps(&hold);
      PrepareWorkspace(hold, &ws);
      collision::RobotData d(robot);
      collision::CalcForwardKinematics(robot, c.Q.col(cand), &d);
      const int S = static_cast<int>(radii.size());
      collision::RobotSpheresTrajectory rs;
      rs.radii = radii;
      rs.links = links;
      rs.centres.resize(3, static_cast<Eigen::Index>(wait_steps) * S);
      for (int w = 0; w < wait_steps; ++w) rs.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = d.p_WS;
      // Safe when the union bound over the people stays below the threshold.
      std::vector<std::vector<double>> shares(static_cast<std::size_t>(wait_steps));
      for (const Problem::Person& person : hold.people) {
        rs.steps.assign(person.steps.begin() + cand + 1, person.steps.begin() + cand + 1 + wait_steps);
        collision::TrajectoryBoundWorkspace bw(S, person.prediction->num_spheres());
        std::vector<collision::WaypointBound> out;
        collision::EvaluateTrajectoryBound(*person.prediction, rs, collision::TrajectoryBoundParams{}, &bw, &out);
        for (int w = 0; w < wait_steps; ++w) shares[static_cast<std::size_t>(w)].push_back(out[w].bound);
      }
      bool safe = true;
      for (const auto& b : shares) safe = safe && cell::UnionBound(b) < Threshold();
      // And the separation monitor must let it stand there (predict_ssm).
      if (safe && SsmLastWaypoint(hold) >= at->ssm_from) {
        Eigen::MatrixXd held(at->nq, hold.n + 1);
        held.leftCols(cand + 1) = c.Q.leftCols(cand + 1);
        for (int w = 0; w < wait_steps; ++w) held.col(cand + 1 + w) = c.Q.col(cand);
        safe = JudgeSsm(hold, held, at->ssm_from, hold.n, &ws).ok();
      }
      if (safe) {
        j = cand;
        break;
      }
    }
  }
  Eigen::MatrixXd next(at->nq, at->n + 1 + wait_steps);
  next.leftCols(j + 1) = src.leftCols(j + 1);
  for (int w = 0; w < wait_steps; ++w) next.col(j + 1 + w) = src.col(j);
  next.rightCols(at->n - j) = src.rightCols(at->n - j);
  next.col(next.cols() - 1) = at->q_goal;
  at->base = next;
  at->n += wait_steps;
  at->k = j + 1 + wait_steps;
}

}  // namespace iplan::planning::internal
