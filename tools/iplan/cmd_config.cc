// `iplan config defaults NAME`: the declared parameters of a parameter struct
// (its Serialize), with their defaults and docs, as YAML or as the Markdown
// table docs/configuration.md carries (the tests compare the two).
#include <iostream>
#include <map>
#include <string>

#include "services/collision_risk/risk_config.h"
#include "services/cloud/core/cloud_settings.h"
#include "command_registry.h"
#include "services/intent/core/intent_settings.h"
#include "services/robot_sim/core/robot_sim_settings.h"
#include "services/supervisor/core/supervisor_settings.h"
#include "services/supervisor/core/task_planner.h"
#include "iplan/collision/human_model.h"
#include "iplan/core/params.h"
#include "iplan/framework/node.h"
#include "services/perception/perception_settings.h"
#include "iplan/safety/safety_params.h"
#include "iplan/planning/planner_params.h"
#include "services/trajopt/trajopt_config.h"

namespace {

using iplan::core::ParamDoc;

// Every struct declared with Serialize that a configuration file holds, by
// the name this command takes, with where its keys live.
const std::map<std::string, std::pair<std::string, std::vector<ParamDoc>(*)()>>& Structs() {
  static const std::map<std::string, std::pair<std::string, std::vector<ParamDoc> (*)()>> structs = {
      {"planner",
       {"config/planner.yaml (top level); PlannerParams",
        [] { return iplan::core::DescribeParams(iplan::planning::PlannerParams{}); }}},
      {"safety",
       {"config/safety.yaml (top level, named by `safety:` in collision_risk.yaml and trajopt.yaml); SafetyParams: "
        "the one source of delta_cl and iso_ts_15066 for monitor, planner, benchmark and cell-check",
        [] { return iplan::core::DescribeParams(iplan::safety::SafetyParams{}); }}},
      {"intent",
       {"config/intent.yaml, section intent; IntentSettings (IntentEstimatorParams' keys inline)",
        [] { return iplan::core::DescribeParams(iplan::intent_service::IntentSettings{}); }}},
      {"cloud",
       {"config/cloud.yaml, section cloud; CloudSettings (the pipeline file is CloudParams)",
        [] { return iplan::core::DescribeParams(iplan::cloud_service::CloudSettings{}); }}},
      {"collision-risk",
       {"config/collision_risk.yaml, section collision_risk; RiskSettings (RiskParams' keys inline, SsmParams under "
        "iso_ts_15066; with `safety:` delta_cl and iso_ts_15066 come from the safety file)",
        [] { return iplan::core::DescribeParams(iplan::collision_risk::RiskSettings{}); }}},
      {"perception",
       {"config/perception.yaml, section perception; PerceptionSettings",
        [] { return iplan::core::DescribeParams(iplan::perception::PerceptionSettings{}); }}},
      {"node",
       {"section node of every service's file; NodeSettings (NodeOptions' keys inline)",
        [] { return iplan::core::DescribeParams(iplan::framework::NodeSettings{}); }}},
      {"replanner",
       {"config/trajopt.yaml, section trajopt; ReplannerParams",
        [] { return iplan::core::DescribeParams(iplan::trajopt::ReplannerParams{}); }}},
      {"trajopt",
       {"config/trajopt.yaml, section trajopt; TrajoptSettings, then ReplannerParams (same section)",
        [] {
          std::vector<ParamDoc> docs = iplan::core::DescribeParams(iplan::trajopt::TrajoptSettings{});
          const std::vector<ParamDoc> replanner = iplan::core::DescribeParams(iplan::trajopt::ReplannerParams{});
          docs.insert(docs.end(), replanner.begin(), replanner.end());
          return docs;
        }}},
      {"supervisor",
       {"config/supervisor.yaml, section supervisor; SupervisorSettings (QLearningParams' keys inline)",
        [] { return iplan::core::DescribeParams(iplan::supervisor::SupervisorSettings{}); }}},
      {"robot-sim",
       {"config/robot_sim.yaml, section robot_sim; RobotSimSettings (SimulatorParams' keys inline)",
        [] { return iplan::core::DescribeParams(iplan::robot_sim::RobotSimSettings{}); }}},
      {"task-graph",
       {"config/tasks/*.yaml (top level); TaskGraph",
        [] { return iplan::core::DescribeParams(iplan::supervisor::TaskGraph{}); }}},
      {"human-body",
       {"config/humans/*.yaml (top level); HumanBodyParams",
        [] { return iplan::core::DescribeParams(iplan::collision::HumanBodyParams{}); }}},
  };
  return structs;
}

void PrintYaml(const std::string& where, const std::vector<ParamDoc>& docs) {
  std::cout << "# " << where << ": defaults\n";
  for (const ParamDoc& d : docs) std::cout << d.key << ": " << d.value << "  # " << d.doc << "\n";
}

const bool kRegistered = iplan::cli::RegisterCommand("config", [](CLI::App& app) {
  CLI::App* config = app.add_subcommand("config", "Parameter declarations (docs/configuration.md)");
  config->require_subcommand(1);
  auto name = std::make_shared<std::string>();
  auto markdown = std::make_shared<bool>(false);
  std::string names;
  for (const auto& [n, s] : Structs()) names += (names.empty() ? "" : ", ") + n;
  CLI::App* defaults = config->add_subcommand(
      "defaults",
      "Print the keys of a parameter struct with their defaults and one-line docs (units first), "
      "from the struct's own declaration. Exit code 0, 2 for an unknown name.");
  defaults->add_option("name", *name, "one of: " + names)->required();
  defaults->add_flag("--markdown", *markdown, "the Markdown table of docs/configuration.md instead of YAML");
  defaults->callback([name, markdown] {
    const auto it = Structs().find(*name);
    if (it == Structs().end()) {
      std::cerr << "iplan config defaults: unknown parameter struct '" << *name << "'\n";
      iplan::cli::SetExitCode(2);
      return;
    }
    const std::vector<ParamDoc> docs = it->second.second();
    if (*markdown) {
      std::cout << iplan::core::ParamsMarkdownTable(docs);
    } else {
      PrintYaml(it->second.first, docs);
    }
  });
});

}  // namespace
