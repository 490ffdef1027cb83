#include "cell_config.h"

#include <filesystem>
#include <stdexcept>

#include "services/intent/core/intent_settings.h"
#include "services/robot_sim/core/robot_sim_settings.h"
#include "services/supervisor/core/supervisor_settings.h"
#include "services/supervisor/core/task_goals.h"
#include "services/supervisor/core/task_planner.h"
#include "iplan/core/params.h"
#include "iplan/collision/scene.h"
#include "iplan/framework/config.h"
#include "iplan/framework/service_file.h"
#include "iplan/planning/planner_params.h"
#include "services/collision_risk/risk_config.h"
#include "services/perception/perception_settings.h"
#include "services/trajopt/trajopt_config.h"

namespace iplan::cell_sim {
namespace {

namespace fs = std::filesystem;

Eigen::VectorXd ToEigen(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

BenchmarkSetup CellConfig::MakeSetup() const {
  BenchmarkSetup s;
  s.models.planner = planner.get();
  s.models.body = body.get();
  s.models.monitor = monitor.get();
  s.models.replanner = replanner;
  s.models.simulator = simulator;
  s.loop = loop;
  s.estimator = estimator;
  s.person = person;
  s.sensor_rate_hz = sensor_rate_hz;
  s.sensor_noise_std = sensor_noise_std;
  s.constant_position.sensor_noise_std = sensor_noise_std;
  s.constant_velocity.sensor_noise_std = sensor_noise_std;
  s.tasks = tasks;
  return s;
}

CellBenchmarkSetup CellConfig::MakeCellSetup() const {
  CellBenchmarkSetup s;
  s.base = MakeSetup();
  s.graph = graph;
  s.learning = learning;
  s.tracker = tracker;
  s.pause_between_tasks = pause_between_tasks;
  return s;
}

CellConfig LoadCellConfig(const std::string& dir, int planner_threads, const std::string& robot_file) {
  if (planner_threads < 0) throw std::runtime_error("planner threads must be >= 0");
  auto file = [&](const std::string& name) {
    const fs::path p = fs::path(dir) / (name + ".yaml");
    if (!fs::exists(p)) throw std::runtime_error("no " + name + ".yaml in " + dir);
    return p.string();
  };
  CellConfig c;
  c.dir = dir;

  // The trajectory optimiser and the models it names.
  // Every file is read as its service reads it (framework::ServiceFile):
  // the same keys, defaults and checks.
  trajopt::TrajoptConfig topt = trajopt::LoadTrajoptConfig(file("trajopt"), robot_file);
  c.replanner = topt.replanner;
  // Simulated time: a wall-clock budget would make the benchmark depend on
  // the machine's load; it plans every cycle to the end.
  c.replanner.cycle_budget = 0.0;
  planning::PlannerParams pp = trajopt::LoadPlannerParams(topt);  // delta_cl, SSM: the cell's safety file
  if (planner_threads > 0) pp.num_threads = planner_threads;
  c.planner = std::make_unique<planning::Planner>(collision::LoadRobotModel(topt.robot_file),
                                                  collision::LoadSceneParams(topt.scene_file), pp);
  c.body = std::make_unique<collision::HumanBodyModel>(collision::LoadHumanBodyParams(topt.human_body_file));

  // The collision-risk monitor, as its service builds it.
  collision_risk::RiskConfig risk = collision_risk::LoadRiskConfig(file("collision_risk"), robot_file);
  c.monitor = std::make_unique<collision_risk::RiskMonitor>(collision_risk::MakeRiskMonitor(risk));
  c.loop.monitor_rate_hz = risk.rate_hz;

  // The simulated robot.
  robot_sim::RobotSimSettings sim;
  framework::ServiceFile(file("robot_sim")).ReadSection("robot_sim", &sim).Finish();
  c.loop.control_rate_hz = sim.control_rate_hz;
  c.loop.joint_state_rate_hz = sim.publish_rate_hz;
  c.simulator = sim.simulator;

  // The supervisor: task graph, resume hysteresis, the task planner's parameters.
  framework::ServiceFile vconf(file("supervisor"));
  supervisor::SupervisorSettings settings;
  vconf.ReadSection("supervisor", &settings).Finish();
  c.loop.resume_delay = settings.resume_delay;
  supervisor::TaskGraph graph = supervisor::LoadTaskGraph(vconf.ResolvePath(settings.task_graph));
  c.goal_notes = supervisor::ResolveTaskGoals(*c.planner, &graph);  // poses: the planner's IK for this robot
  for (const auto& t : graph.tasks) c.tasks.push_back({t.name, ToEigen(t.goal), ToEigen(t.retreat)});
  c.graph = std::move(graph);
  c.learning = settings.learning;
  c.tracker = settings.tracker;
  c.pause_between_tasks = settings.pause_between_tasks;

  // The sensor and the synthetic person.
  perception::PerceptionSettings perception;
  framework::ServiceFile(file("perception")).ReadSection("perception", &perception).Finish();
  c.sensor_rate_hz = perception.rate_hz;
  c.person = perception.synthetic.Person();
  c.sensor_noise_std = c.person.noise_stddev;

  // The intent estimator's settings.
  intent_service::IntentSettings intent;
  framework::ServiceFile(file("intent")).ReadSection("intent", &intent).Finish();
  c.estimator = intent.estimator;
  return c;
}

}  // namespace iplan::cell_sim
