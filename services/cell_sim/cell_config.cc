#include "cell_config.h"

#include <filesystem>
#include <stdexcept>

#include "core/robot_sim_settings.h"
#include "core/supervisor_settings.h"
#include "core/task_goals.h"
#include "core/task_planner.h"
#include "iplan/core/params.h"
#include "iplan/collision/scene.h"
#include "iplan/framework/config.h"
#include "iplan/planning/planner_params.h"
#include "risk_config.h"
#include "synthetic_config.h"
#include "trajopt_config.h"

namespace iplan::cell_sim {
namespace {

namespace fs = std::filesystem;

// Tools read part of each service's file: its values are checked, its other
// keys are the services' business.
void Check(const framework::ConfigSection& c) {
  if (c.Problems().empty()) return;
  std::string msg;
  for (const auto& p : c.Problems()) msg += (msg.empty() ? "" : "\n") + p;
  throw std::runtime_error(msg);
}

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
  framework::ConfigSection tconf = framework::ConfigSection::Load(file("trajopt"));
  framework::ConfigSection tsec = tconf.Section("trajopt");
  trajopt::TrajoptConfig topt = trajopt::ReadTrajoptConfig(tsec);
  Check(tconf);
  if (!robot_file.empty()) topt.robot_file = robot_file;
  if (const std::string why = topt.replanner.Validate(); !why.empty()) throw std::runtime_error(file("trajopt") + ": " + why);
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
  framework::ConfigSection rconf = framework::ConfigSection::Load(file("collision_risk"));
  framework::ConfigSection rsec = rconf.Section("collision_risk");
  collision_risk::RiskConfig risk = collision_risk::ReadRiskConfig(rsec);
  Check(rconf);
  if (!robot_file.empty()) risk.robot_file = robot_file;
  if (const std::string why = risk.params.Validate(); !why.empty()) throw std::runtime_error(file("collision_risk") + ": " + why);
  c.monitor = std::make_unique<collision_risk::RiskMonitor>(collision_risk::MakeRiskMonitor(risk));
  c.loop.monitor_rate_hz = risk.rate_hz;

  // The simulated robot.
  framework::ConfigSection sconf = framework::ConfigSection::Load(file("robot_sim"));
  framework::ConfigSection ssec = sconf.Section("robot_sim");
  robot_sim::RobotSimSettings sim;
  core::ReadParams(ssec, &sim);  // the service's keys and ranges
  c.loop.control_rate_hz = sim.control_rate_hz;
  c.loop.joint_state_rate_hz = sim.publish_rate_hz;
  c.simulator = sim.simulator;
  Check(sconf);

  // The supervisor: task graph and resume hysteresis.
  framework::ConfigSection vconf = framework::ConfigSection::Load(file("supervisor"));
  framework::ConfigSection vsec = vconf.Section("supervisor");
  supervisor::SupervisorSettings settings;
  core::ReadParams(vsec, &settings);  // the service's keys and ranges
  c.loop.resume_delay = settings.resume_delay;
  Check(vconf);
  supervisor::TaskGraph graph = supervisor::LoadTaskGraph(vconf.ResolvePath(settings.task_graph));
  c.goal_notes = supervisor::ResolveTaskGoals(*c.planner, &graph);  // poses: the planner's IK for this robot
  for (const auto& t : graph.tasks) c.tasks.push_back({t.name, ToEigen(t.goal), ToEigen(t.retreat)});

  // The sensor and the synthetic person.
  framework::ConfigSection pconf = framework::ConfigSection::Load(file("perception"));
  framework::ConfigSection psec = pconf.Section("perception");
  psec.Read("rate_hz", &c.sensor_rate_hz, framework::InRange(0.5, 1000.0));
  framework::ConfigSection syn = psec.Section("synthetic");
  perception::ScriptStart start;
  c.person = perception::ReadSyntheticPerson(syn, &start);
  Check(pconf);
  if (const std::string why = c.person.Validate(); !why.empty()) {
    throw std::runtime_error(file("perception") + ": key 'perception.synthetic': " + why);
  }
  c.sensor_noise_std = c.person.noise_stddev;

  // The intent estimator's settings.
  framework::ConfigSection iconf = framework::ConfigSection::Load(file("intent"));
  framework::ConfigSection isec = iconf.Section("intent");
  isec.Read("body_timeout", &c.estimator.body_timeout, framework::Positive<double>());
  isec.Read("max_gap", &c.estimator.max_gap, framework::Positive<double>());
  isec.Read("max_bodies", &c.estimator.max_bodies, framework::InRange(1, 1000));
  Check(iconf);
  return c;
}

}  // namespace iplan::cell_sim
