#include "iplan/framework/enclaves.h"

#include "iplan/framework/topics.h"

namespace iplan::framework {

std::string EnclaveName(const std::string& service_name) { return "iplan-" + service_name; }

std::vector<dds::EnclaveGrant> CellEnclaves() {
  using namespace topics;
  // What each service's OnConfigure advertises and subscribes (the
  // supervisor: every topic `supervisor.watch` may name); every node also
  // publishes its diagnostics.
  const std::string diag = Diagnostics().name;
  std::vector<dds::EnclaveGrant> g = {
      {EnclaveName("perception"),
       {HumanSkeleton().name, HumanTruth().name, DepthPoints().name, diag},
       {TaskCommand().name, JointStates().name}},
      {EnclaveName("cloud"), {Obstacles().name, HumanPoints().name, diag}, {DepthPoints().name, JointStates().name}},
      {EnclaveName("intent"), {ActionBelief().name, HumanPrediction().name, diag}, {HumanSkeleton().name}},
      {EnclaveName("collision_risk"),
       {CollisionRisk().name, SafetyPermit().name, diag},
       {JointStates().name, RobotTrajectory().name, HumanSkeleton().name, HumanPrediction().name,
        HumanPoints().name}},
      {EnclaveName("trajopt"),
       {RobotTrajectory().name, TaskOutcome().name, PlanStatus().name, diag},
       {JointStates().name, HumanPrediction().name, SafetyPermit().name, TaskCommand().name, Obstacles().name}},
      {EnclaveName("robot_sim"),
       {JointStates().name, TfStatic().name, diag},
       {RobotTrajectory().name, SafetyPermit().name, HumanTruth().name}},
      {EnclaveName("supervisor"),
       {TaskCommand().name, SafetyPermit().name, diag},
       {HumanSkeleton().name, HumanPrediction().name, ActionBelief().name, JointStates().name,
        RobotTrajectory().name, CollisionRisk().name, TaskOutcome().name}},
  };
  dds::EnclaveGrant observer{kObserverEnclave, {}, {}};
  for (const auto& t : All()) observer.subscribe.push_back(t.name);
  g.push_back(observer);
  return g;
}

}  // namespace iplan::framework
