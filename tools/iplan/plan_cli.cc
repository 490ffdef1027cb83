#include "plan_cli.h"

#include <exception>
#include <ostream>

#include <nlohmann/json.hpp>

#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/planning/planner.h"
#include "iplan/planning/prediction_io.h"

namespace iplan::planning {
namespace {

// The planner's parameters: the config's (or the defaults, adapted to the
// robot) with the command line's overrides.
PlannerParams Params(const PlanCliOptions& o, const collision::RobotModel& robot) {
  PlannerParams params = o.config.empty() ? PlannerParams{} : LoadPlannerParams(o.config);
  if (o.threads) params.num_threads = *o.threads;
  if (o.seed) params.seed = *o.seed;
  // The defaults are the Panda's; for another arm, its own links.
  if (o.config.empty()) params = AdaptLinksToRobot(params, robot);
  if (o.tool_link) params.end_effector_link = *o.tool_link;
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("planner params: " + why);
  return params;
}

}  // namespace

int RunPlanCommand(const PlanCliOptions& o, std::ostream& out, std::ostream& err) {
  try {
    if (o.scene.empty()) throw std::invalid_argument("--scene is required");
    if (o.goal.empty() == o.goal_pose.empty())
      throw std::invalid_argument("give exactly one of --goal and --goal-pose");
    collision::RobotModel robot = collision::LoadRobotModel(o.robot);
    collision::SceneParams scene = collision::LoadSceneParams(o.scene);
    const PlannerParams params = Params(o, robot);
    Planner planner(std::move(robot), std::move(scene), params);
    const int nq = planner.robot().nq;
    auto vec = [&](const std::vector<double>& v, const char* what) {
      if (static_cast<int>(v.size()) != nq)
        throw std::invalid_argument(std::string(what) + " has " + std::to_string(v.size()) +
                                    " values, the robot has " + std::to_string(nq) + " joints");
      return Eigen::Map<const Eigen::VectorXd>(v.data(), nq).eval();
    };
    PlanningRequest req;
    req.start_q = vec(o.start, "--start");
    if (!o.goal.empty()) {
      req.goal = Goal::Joint(vec(o.goal, "--goal"));
    } else {
      if (o.goal_pose.size() != 7)
        throw std::invalid_argument("--goal-pose needs x,y,z,qx,qy,qz,qw (7 values), got " +
                                    std::to_string(o.goal_pose.size()));
      const auto& g = o.goal_pose;
      Eigen::Quaterniond R(g[6], g[3], g[4], g[5]);
      if (!(std::abs(R.norm() - 1.0) < 1e-3))
        throw std::invalid_argument("--goal-pose quaternion must have unit norm, got norm " +
                                    std::to_string(R.norm()));
      req.goal = Goal::Pose(Eigen::Vector3d(g[0], g[1], g[2]), R.normalized());
    }
    PredictionFile pred;
    std::unique_ptr<collision::HumanBodyModel> body;
    if (!o.prediction.empty()) {
      body = std::make_unique<collision::HumanBodyModel>(
          o.human.empty() ? collision::HumanBodyParams::DefaultUpperBody()
                          : collision::LoadHumanBodyParams(o.human));
      pred = LoadPredictionFile(o.prediction, *body);
      req.people = {{pred.prediction.get(), pred.dt, pred.start_time}};
    }
    const PlanningResult r = planner.Plan(req);
    if (o.json) {
      nlohmann::ordered_json j;
      j["success"] = r.success();
      j["planning_time_s"] = r.planning_time;
      j["max_collision_bound"] = r.max_bound;
      j["delay_s"] = r.delay;
      nlohmann::ordered_json traj;
      traj["dt"] = r.dt;
      nlohmann::ordered_json pos = nlohmann::ordered_json::array();
      for (Eigen::Index i = 0; i < r.positions.cols(); ++i) {
        nlohmann::ordered_json w = nlohmann::ordered_json::array();
        for (Eigen::Index k = 0; k < r.positions.rows(); ++k) w.push_back(r.positions(k, i));
        pos.push_back(w);
      }
      traj["positions"] = pos;
      j["trajectory"] = traj;
      out << j.dump() << "\n";
    } else {
      out << "status: " << ToString(r.status) << (r.success() ? "" : " (" + r.reason + ")") << "\n"
          << "planning time: " << r.planning_time << " s\n"
          << "waypoints: " << r.positions.cols() << " at dt " << r.dt << " s\n"
          << "waits: " << r.num_waits << ", delay " << r.delay << " s\n"
          << "max collision bound: " << r.max_bound << "\n"
          << "min clearance: " << r.min_clearance << " m\n"
          << "cost: " << r.cost << " (optimiser " << r.winning_optimizer << ", " << r.num_feasible
          << " feasible)\n";
    }
    return r.success() ? 0 : 1;
  } catch (const std::exception& e) {
    err << "iplan plan: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace iplan::planning
