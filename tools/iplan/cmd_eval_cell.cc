// `iplan eval cell`: the episode benchmark (issue 26). Whole episodes of the
// task graph in one process and in simulated time through the services'
// cores, the supervisor's task planner choosing every task, against the
// cell's synthetic person whose actions are drawn from the task graph's
// human_graph; per predictor (each with its own task planner, learning over
// the episodes) the episode time, the robot's idle time (stopped, or
// standing while tasked), protective stops, contacts and tasks done, and
// the ratios against `none`. The work is done by
// services/cell_sim/core/cell_benchmark; this file parses options, prepares
// the intent model as `iplan demo --prepare-only` does, and prints.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "tools/cell_sim/core/cell_benchmark.h"
#include "command_registry.h"
#include "dds_cell_model.h"
#include "eval_cell.h"
#include "eval_common.h"
#include "iplan/core/atomic_file.h"

namespace iplan::cli {
namespace {

using cell_sim::Predictor;
using eval_common::Json;
using eval_common::SpreadText;

struct CellOptions {
  std::string predictors = eval_common::kAllPredictors;
  int episodes = 30;
  uint64_t seed = 1;
  std::string json_file, config_dir, model_dir, robot;
  int threads = 1;
  int trace = -1;  // episode whose runs are traced (-1: none)
  double episode_limit = 120, time_limit = 20;
  double anticipation_weight = -1;  // < 0: supervisor.yaml's
  int anticipation_depth = 0;       // 0: supervisor.yaml's
  double duration_weight = -1;      // < 0: supervisor.yaml's
  double travel_weight = -1;        // < 0: supervisor.yaml's
  double oracle_error = 0;          // m, CellBenchmarkSetup::oracle_error_std
  bool retrain = false, quiet = false;
};

const char* kCommand = "iplan eval cell";

Json SpreadJsonWithTotal(const cell_sim::Spread& s, double total) {
  Json j = eval_common::SpreadJson(s);
  j["total"] = total;
  return j;
}

// One predictor's run of one episode, for the JSON.
Json EpisodeJson(const cell_sim::EpisodeSpec& e, const cell_sim::CellEpisodeResult& r) {
  Json j;
  j["episode"] = e.index;
  j["predictor"] = cell_sim::ToString(r.predictor);
  j["complete"] = r.complete;
  j["episode_time_s"] = r.episode_time;
  j["robot_idle_s"] = r.robot_idle;
  j["stop_time_s"] = r.stop_time;
  j["planner_delay_s"] = r.planner_delay;
  j["protective_stops"] = r.protective_stops;
  j["tasks_done"] = r.tasks_done;
  j["robot_moving_contacts"] = r.robot_moving_contacts;
  j["robot_at_rest_contacts"] = r.robot_at_rest_contacts;
  j["min_separation_m"] = r.min_separation;
  j["episodes_learned"] = r.episodes_learned;
  Json tasks = Json::array();
  for (const auto& t : r.tasks) {
    tasks.push_back(Json{{"task", t.task},
                         {"person_action", t.person_action},
                         {"person_for_s", t.person_for},
                         {"believed_action", t.believed_action},
                         {"believed_for_s", t.believed_for},
                         {"expected_conflict_s", t.expected_conflict},
                         {"command_s", t.result.command_time},
                         {"succeeded", t.result.finished && t.result.status == trajopt::TaskStatus::kSucceeded},
                         {"task_time_s", t.result.task_time},
                         {"stop_time_s", t.result.stop_time},
                         {"wait_time_s", t.result.wait_time},
                         {"protective_stops", t.result.protective_stops}});
  }
  j["tasks"] = std::move(tasks);
  return j;
}

// The person's drawn actions of an episode, for the JSON (shared by every predictor).
Json PersonJson(const cell_sim::EpisodeSpec& e) {
  Json actions = Json::array();
  for (const auto& a : e.actions) actions.push_back(Json{{"action", a.action}, {"start_s", a.start}, {"duration_s", a.duration}});
  return Json{{"episode", e.index}, {"noise_seed", e.noise_seed}, {"person_seed", e.person_seed}, {"actions", actions}};
}

Json SummaryJson(const cell_sim::CellSummary& s) {
  Json j;
  j["episodes"] = s.episodes;
  j["episodes_complete"] = s.complete;
  j["episode_time_s"] = eval_common::SpreadJson(s.episode_time);
  j["robot_idle_s"] = SpreadJsonWithTotal(s.robot_idle, s.robot_idle_total);
  j["protective_stops"] = s.protective_stops;
  j["robot_moving_contacts"] = s.robot_moving_contacts;
  j["robot_at_rest_contacts"] = s.robot_at_rest_contacts;
  j["tasks_done"] = s.tasks_done;
  j["tasks_total"] = s.tasks_total;
  if (s.choices_with_belief > 0) {
    j["belief_at_choice"] = Json{{"choices", s.choices_with_belief},
                                 {"right", s.belief_right},
                                 {"age_error_s", s.belief_right > 0 ? eval_common::SpreadJson(s.age_error) : Json()}};
  }
  if (s.has_reference) {
    j["vs_none"] = Json{{"episode_time_median_ratio", eval_common::RatioJson(s.episode_time_ratio)},
                        {"episode_time_paired_ratio", eval_common::SpreadJson(s.episode_time_paired_ratio)},
                        {"robot_idle_median_ratio", eval_common::RatioJson(s.robot_idle_ratio)},
                        {"robot_idle_paired_ratio", eval_common::SpreadJson(s.robot_idle_paired_ratio)}};
  }
  return j;
}

const cell_sim::CellSummary* Find(const std::vector<cell_sim::CellSummary>& summary, Predictor p) {
  for (const auto& s : summary) {
    if (s.predictor == p) return &s;
  }
  return nullptr;
}

// The gain over none of `reference` (oracle or oracle-action) that the model
// recovers, per figure, for the JSON and the table; null unless all three ran.
Json GainJson(const std::vector<cell_sim::CellSummary>& summary, Predictor reference) {
  const auto* none = Find(summary, Predictor::kNone);
  const auto* model = Find(summary, Predictor::kModel);
  const auto* oracle = Find(summary, reference);
  if (!none || !model || !oracle) return Json(nullptr);
  return Json{{"episode_time", eval_common::RatioJson(cell_sim::GainRecovered(none->episode_time.median, model->episode_time.median,
                                                                      oracle->episode_time.median))},
              {"robot_idle", eval_common::RatioJson(cell_sim::GainRecovered(none->robot_idle.median, model->robot_idle.median,
                                                                    oracle->robot_idle.median))}};
}

void PrintTable(const std::vector<cell_sim::CellSummary>& summary) {
  std::cout << std::left << std::setw(19) << "predictor" << std::setw(26) << "episode time s" << std::setw(26)
            << "robot idle s (total)" << std::setw(7) << "stops" << std::setw(9) << "moving" << std::setw(9)
            << "at rest" << std::setw(12) << "tasks done" << "complete\n";
  for (const auto& s : summary) {
    std::cout << std::left << std::setw(19) << cell_sim::ToString(s.predictor) << std::setw(26)
              << SpreadText(s.episode_time, 2) << std::setw(26)
              << (SpreadText(s.robot_idle, 2) + " (" + Fixed(s.robot_idle_total, 1) + ")") << std::setw(7)
              << s.protective_stops << std::setw(9) << s.robot_moving_contacts << std::setw(9) << s.robot_at_rest_contacts
              << std::setw(12) << (std::to_string(s.tasks_done) + "/" + std::to_string(s.tasks_total)) << s.complete << "/"
              << s.episodes << "\n";
  }
  for (const auto& s : summary) {
    if (s.choices_with_belief == 0) continue;
    std::cout << "  " << cell_sim::ToString(s.predictor) << "'s task choices: the person's action right in "
              << s.belief_right << " of " << s.choices_with_belief;
    if (s.belief_right > 0) std::cout << ", its age off by " << SpreadText(s.age_error, 2) << " s there";
    std::cout << "\n";
  }
  if (summary.empty() || !summary.front().has_reference) return;
  std::cout << "\nagainst none: ratio of medians (median of the paired per-episode ratios [p10, p90])\n";
  for (const auto& s : summary) {
    std::cout << "  " << std::left << std::setw(19) << cell_sim::ToString(s.predictor) << "episode time "
              << Fixed(s.episode_time_ratio, 2) << " (" << SpreadText(s.episode_time_paired_ratio, 2) << ")  robot idle "
              << Fixed(s.robot_idle_ratio, 2) << " (" << SpreadText(s.robot_idle_paired_ratio, 2) << ")\n";
  }
  for (Predictor reference : {Predictor::kOracle, Predictor::kOracleAction}) {
    const Json gain = GainJson(summary, reference);
    if (gain.is_null()) continue;
    auto text = [](const Json& v) { return v.is_null() ? std::string("n/a") : Fixed(v.get<double>(), 2); };
    std::cout << "model recovers of the " << cell_sim::ToString(reference)
              << "'s gain over none (medians): episode time " << text(gain["episode_time"]) << ", robot idle "
              << text(gain["robot_idle"]) << "\n";
  }
}

// The JSON's run settings and figures per predictor (the people and the
// episodes follow them).
Json HeaderJson(const CellOptions& o, const cell_sim::CellBenchmarkSetup& setup,
                const std::vector<cell_sim::CellSummary>& summary, std::size_t num_episodes) {
  Json per = Json::object();
  for (const auto& s : summary) per[cell_sim::ToString(s.predictor)] = SummaryJson(s);
  Json doc;
  doc["command"] = kCommand;
  doc["seed"] = o.seed;
  doc["num_episodes"] = num_episodes;
  doc["episode_limit_s"] = o.episode_limit;
  doc["time_limit_s"] = o.time_limit;
  doc["anticipation_weight"] = setup.learning.anticipation_weight;
  doc["anticipation_depth"] = setup.learning.anticipation_depth;
  doc["duration_weight"] = setup.learning.duration_weight;
  doc["travel_weight"] = setup.learning.travel_weight;
  doc["oracle_error_std_m"] = setup.oracle_error_std;
  doc["predictors"] = std::move(per);
  doc["model_recovers_oracle_gain"] = GainJson(summary, Predictor::kOracle);
  if (Find(summary, Predictor::kOracleAction)) {
    doc["model_recovers_oracle_action_gain"] = GainJson(summary, Predictor::kOracleAction);
  }
  return doc;
}

// Sets up the benchmark; prints why and returns false on a failure.
bool Prepare(const CellOptions& o, eval_common::CellInputs* in, cell_sim::CellBenchmarkSetup* setup,
             std::vector<cell_sim::EpisodeSpec>* episodes) {
  try {
    eval_common::ReadConfiguration(eval_common::ConfigDir(o.config_dir), o.robot, o.threads, in);
    // A cell the benchmark cannot run is refused before the model is trained.
    cell_sim::CellBenchmarkSetup probe = in->cell.MakeCellSetup();
    probe.base.intent_model = std::make_shared<const intent::IntentModel>();
    if (const std::string why = probe.Validate(); !why.empty()) throw std::runtime_error(why);
    eval_common::PrepareIntentModel(o.model_dir, o.retrain, in);
    *setup = in->cell.MakeCellSetup();
    setup->base.intent_model = in->intent_model;
    setup->episode_limit = o.episode_limit;
    setup->task_time_limit = o.time_limit;
    if (o.anticipation_weight >= 0) setup->learning.anticipation_weight = o.anticipation_weight;
    if (o.anticipation_depth > 0) setup->learning.anticipation_depth = o.anticipation_depth;
    if (o.duration_weight >= 0) setup->learning.duration_weight = o.duration_weight;
    if (o.travel_weight >= 0) setup->learning.travel_weight = o.travel_weight;
    setup->oracle_error_std = o.oracle_error;
    try {
      cell_sim::CalibrateBaselines(RecordCellDemonstrations(in->cell.person), &setup->base);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("baseline calibration: ") + e.what());
    }
    *episodes = cell_sim::MakeCellEpisodes(*setup, o.episodes, o.seed);
  } catch (const std::exception& e) {
    std::cerr << kCommand << ": " << e.what() << "\n";
    return false;
  }
  return true;
}

void PrintProgress(const cell_sim::EpisodeSpec& e, std::size_t count, const std::vector<cell_sim::CellEpisodeResult>& row,
                   double wall) {
  std::cerr << "  episode " << std::setw(3) << e.index + 1 << "/" << count << " person " << e.actions.front().action;
  for (std::size_t i = 1; i < e.actions.size() && i < 4; ++i) std::cerr << "," << e.actions[i].action;
  std::cerr << ":";
  for (const auto& r : row) {
    std::cerr << " " << cell_sim::ToString(r.predictor) << " " << Fixed(r.episode_time, 1) << " s/idle "
              << Fixed(r.robot_idle, 1) << "/" << r.protective_stops << "st";
  }
  std::cerr << " (" << Fixed(wall, 1) << " s)\n";
}

int RunCell(const CellOptions& o) {
  const std::optional<std::vector<Predictor>> parsed = eval_common::ParsePredictors(o.predictors, kCommand);
  if (!parsed) return 2;
  if (o.episodes < 1) {
    std::cerr << kCommand << ": --episodes must be at least 1, got " << o.episodes << "\n";
    return 2;
  }
  if (!(o.episode_limit > 0) || !(o.time_limit > 0)) {
    std::cerr << kCommand << ": --episode-limit and --time-limit must be > 0 s\n";
    return 2;
  }
  const std::vector<Predictor>& predictors = *parsed;
  const auto wall0 = std::chrono::steady_clock::now();
  eval_common::CellInputs in;
  cell_sim::CellBenchmarkSetup setup;
  std::vector<cell_sim::EpisodeSpec> episodes;
  if (!Prepare(o, &in, &setup, &episodes)) return 2;
  std::cout << kCommand << ": " << episodes.size() << " episodes, seed " << o.seed << ", predictors";
  for (Predictor p : predictors) std::cout << " " << cell_sim::ToString(p);
  std::cout << "\n  configuration " << in.dir << "\n  " << in.model.summary << "\n  task planner: anticipation_weight "
            << setup.learning.anticipation_weight << ", anticipation_depth " << setup.learning.anticipation_depth
            << ", duration_weight " << setup.learning.duration_weight << ", travel_weight "
            << setup.learning.travel_weight
            << ", one per predictor, learning over the episodes\n\n";

  std::vector<std::vector<cell_sim::CellEpisodeResult>> results;
  Json runs = Json::array(), people = Json::array();
  try {
    auto planners = cell_sim::MakeCellPlanners(setup, predictors);
    for (const auto& e : episodes) {
      const auto t0 = std::chrono::steady_clock::now();
      setup.base.loop.trace = nullptr;
      if (e.index == o.trace) {
        setup.base.loop.trace = [](double t, const std::string& event) {
          std::cerr << "    " << std::fixed << std::setprecision(2) << std::setw(6) << t << " " << event << "\n";
        };
      }
      results.push_back(cell_sim::RunCellEpisode(setup, e, predictors, &planners));
      if (!o.quiet) {
        PrintProgress(e, episodes.size(), results.back(),
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      people.push_back(PersonJson(e));
      for (const auto& r : results.back()) runs.push_back(EpisodeJson(e, r));
    }
  } catch (const std::exception& e) {
    std::cerr << kCommand << ": " << e.what() << "\n";
    return 1;
  }
  const auto summary = cell_sim::SummarizeCell(predictors, results, static_cast<int>(setup.graph.tasks.size()));
  Json doc = HeaderJson(o, setup, summary, episodes.size());
  doc["people"] = std::move(people);
  doc["episodes"] = std::move(runs);
  PrintTable(summary);
  std::cout << "\nwall time " << Fixed(std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(), 1)
            << " s (not in the JSON)\n";
  if (!o.json_file.empty()) {
    try {
      core::WriteFileAtomically(o.json_file, doc.dump(2) + "\n");
    } catch (const std::exception& e) {
      std::cerr << kCommand << ": cannot write " << o.json_file << ": " << e.what() << "\n";
      return 1;
    }
    std::cout << "JSON written to " << o.json_file << "\n";
  }
  return 0;
}

}  // namespace

void AddEvalCellCommand(CLI::App* eval) {
  auto o = std::make_shared<CellOptions>();
  CLI::App* c = eval->add_subcommand(
      "cell",
      "Episode benchmark: whole episodes of the task graph (config/tasks/table_top.yaml), every task chosen by the\n"
      "supervisor's task planner, through the services' own cores in simulated time (as eval interaction), against the\n"
      "cell's synthetic person whose actions are drawn from the task graph's human_graph (what follows each action\n"
      "with which probability, for how long). The same person, noise and model predictions for every predictor of an\n"
      "episode (paired); each predictor has its own task planner, fresh at the first episode and learning over them.\n"
      "Per predictor: episode time (first command to last outcome; the limit when unfinished), robot idle (stopped, or\n"
      "standing still while tasked), protective stops, contacts with the robot moving / at rest, tasks done; ratios\n"
      "against none and the share of the oracle's gain the model recovers. The task planner gets nothing from none and\n"
      "the baselines, the action belief and how long its action has lasted from model, the true current action, when it\n"
      "ends and the true next action from oracle. oracle-action (not in the default list) plans against the true motion\n"
      "of the person's current action as if it went on for ever, and tells the task planner the true current action and\n"
      "how long it has lasted, not when it ends: the best a forecaster of each action's motion with a perfect recogniser\n"
      "could do. Deterministic for a seed. Exit code 2 on bad input.");
  c->add_option("--predictors", o->predictors,
                "comma-separated predictors to compare (none, constant-position, constant-velocity, model, oracle, "
                "oracle-action)")
      ->capture_default_str();
  c->add_option("--episodes", o->episodes, "number of episodes (>= 1)")->capture_default_str();
  c->add_option("--seed", o->seed, "seed of the episodes (the person's actions, motion and sensor noise)")
      ->capture_default_str();
  c->add_option("--json", o->json_file, "write the figures and every episode's run as JSON to this file");
  c->add_option("--config-dir", o->config_dir, "configuration folder (default: $IPLAN_CONFIG_DIR, installed, or source)");
  c->add_option("--robot", o->robot, "another arm instead of the configured one: a URDF or URDF overlay (docs/robots.md)")
      ->check(CLI::ExistingFile);
  c->add_option("--episode-limit", o->episode_limit, "s an episode may take from its first command")->capture_default_str();
  c->add_option("--time-limit", o->time_limit, "s a task may take before it counts as failed")->capture_default_str();
  c->add_option("--anticipation-weight", o->anticipation_weight,
                "the task planners' anticipation_weight instead of supervisor.yaml's (0: METHOD 6's choice)")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--anticipation-depth", o->anticipation_depth,
                "the task planners' anticipation_depth instead of supervisor.yaml's")
      ->check(CLI::Range(1, 8));
  c->add_option("--duration-weight", o->duration_weight,
                "the task planners' duration_weight (reward per second of a task's time less its delay) instead of "
                "supervisor.yaml's (0: METHOD 6's reward)")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--travel-weight", o->travel_weight,
                "the task planners' travel_weight (choice penalty per second of estimated travel to a task's goal) "
                "instead of supervisor.yaml's (0: off)")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--oracle-error", o->oracle_error,
                "m per axis: the oracles' forecast means are off by an error drawn per frame and joint, N(0, this^2) "
                "at the last step, growing linearly from 0 over the steps (how precise a forecast must be to gain what "
                "they gain)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option("--threads", o->threads, "planner threads (0: as planner_replanning.yaml; results do not depend on it)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  c->add_option("--model-dir", o->model_dir,
                "folder for the intent model when config/models is not writable (default: a temporary folder)");
  c->add_flag("--retrain", o->retrain, "train the intent model again even if a cached one fits");
  c->add_flag("--quiet", o->quiet, "no progress line per episode on stderr");
  c->add_option("--trace", o->trace,
                "print every planning cycle, stop and resume of episode N's runs (0-based) to stderr");
  c->callback([o] { SetExitCode(RunCell(*o)); });
}

}  // namespace iplan::cli
