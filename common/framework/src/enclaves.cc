#include "iplan/framework/enclaves.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "iplan/framework/topics.h"

namespace iplan::framework {

std::string EnclaveName(const std::string& service_name) { return "iplan-" + service_name; }

std::vector<dds::EnclaveGrant> CellEnclaves() {
  using namespace topics;
  // What each service's OnConfigure advertises and subscribes (the
  // supervisor: every topic `supervisor.watch` may name); every node also
  // publishes its diagnostics. Each monitor alone may publish its permit
  // topic: a permit's topic is its authenticated origin (docs/safety.md).
  const std::string diag = Diagnostics().name;
  std::vector<dds::EnclaveGrant> g = {
      {EnclaveName("perception"),
       {HumanSkeleton().name, HumanTruth().name, DepthPoints().name, DepthImage().name, DepthCameraInfo().name, diag},
       {TaskCommand().name, JointStates().name}},
      {EnclaveName("cloud"),
       {Obstacles().name, HumanPoints().name, diag},
       {DepthPoints().name, DepthImage().name, DepthCameraInfo().name, JointStates().name}},
      {EnclaveName("intent"), {ActionBelief().name, HumanPrediction().name, diag}, {HumanSkeleton().name}},
      {EnclaveName("collision_risk"),
       {CollisionRisk().name, CollisionRiskPermit().name, diag},
       {JointStates().name, RobotTrajectory().name, HumanSkeleton().name, HumanPrediction().name,
        HumanPoints().name}},
      {EnclaveName("trajopt"),
       {RobotTrajectory().name, TaskOutcome().name, PlanStatus().name, diag},
       {JointStates().name, HumanPrediction().name, SupervisorPermit().name, TaskCommand().name, Obstacles().name,
        HumanPoints().name}},
      {EnclaveName("robot_sim"),
       {JointStates().name, TfStatic().name, diag},
       {RobotTrajectory().name, SupervisorPermit().name, CollisionRiskPermit().name, HumanTruth().name}},
      {EnclaveName("supervisor"),
       {TaskCommand().name, SupervisorPermit().name, diag},
       {HumanSkeleton().name, HumanPrediction().name, ActionBelief().name, JointStates().name,
        RobotTrajectory().name, CollisionRisk().name, TaskOutcome().name, HumanPoints().name}},
  };
  dds::EnclaveGrant observer{kObserverEnclave, {}, {}};
  for (const auto& t : All()) observer.subscribe.push_back(t.name);
  g.push_back(observer);
  return g;
}

namespace {

bool SameTopics(std::vector<std::string> a, std::vector<std::string> b) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  return a == b;
}

// Why enclave `want` of keystore `dir` is not what the cell needs, or "".
std::string Outdated(const std::string& dir, const dds::EnclaveGrant& want) {
  try {
    const dds::EnclaveGrant has = dds::ReadGrant(dir, want.name);
    if (!SameTopics(has.publish, want.publish) || !SameTopics(has.subscribe, want.subscribe)) {
      return "its permissions grant other topics than this version of the cell uses";
    }
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

}  // namespace

KeystoreReport EnsureCellKeystore(const std::string& dir) {
  namespace fs = std::filesystem;
  KeystoreReport report;
  const std::vector<dds::EnclaveGrant> grants = CellEnclaves();
  std::error_code ec;
  if (!fs::exists(dir, ec) || (fs::is_directory(dir, ec) && fs::is_empty(dir, ec))) {
    try {
      dds::CreateKeystore(dir, grants);
      report.created = true;
      return report;
    } catch (const std::exception&) {
      // Another process may have made it meanwhile: then check that one.
      if (!fs::is_directory(dir, ec) || fs::is_empty(dir, ec)) throw;
    }
  }
  for (const dds::EnclaveGrant& g : grants) {
    const std::string why = Outdated(dir, g);
    if (why.empty()) continue;
    dds::CreateEnclave(dir, g);
    report.reissued.push_back(g.name + ": " + why);
  }
  return report;
}

std::string UserKeystoreDir() {
  const char* data = std::getenv("XDG_DATA_HOME");
  if (data && *data) return std::string(data) + "/iplan/keystore";
  const char* home = std::getenv("HOME");
  if (home && *home) return std::string(home) + "/.local/share/iplan/keystore";
  throw std::runtime_error("no keystore folder: neither XDG_DATA_HOME nor HOME is set (give --security DIR)");
}

}  // namespace iplan::framework
