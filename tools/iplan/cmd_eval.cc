// `iplan eval interaction`: the closed-loop interaction benchmark. Seeded
// scenarios in the cell (a robot task while a recorded or the synthetic
// person moves near or across its path; `--suite shared-space`: hand-overs,
// a parts bin both reach into, co-assembly, the person crossing the path,
// every one bringing the person within reach of the robot's path), each run
// in one process and in simulated time through the services' cores once per
// predictor, and the figures per predictor: task time, protective stops,
// time in stop, minimum true separation, maximum true bound, true contacts
// split into those with the robot moving and at rest (median and [p10, p90]
// over the scenarios, paired ratios against `none`). The work is done by
// services/cell_sim; this file parses options, prepares the intent model as
// `iplan demo --prepare-only` does, and prints.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/cell_sim/cell_config.h"
#include "command_registry.h"
#include "tools/cell_sim/core/interaction_benchmark.h"
#include "dds_cell_model.h"
#include "eval_cell.h"
#include "eval_common.h"
#include "iplan/core/atomic_file.h"
#include "iplan/core/stats.h"
#include "iplan/framework/service.h"
#include "iplan/intent/model_io.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cli {
namespace {

namespace fs = std::filesystem;
using cell_sim::Predictor;
using eval_common::Json;
using eval_common::RatioJson;
using eval_common::SpreadJson;
using eval_common::SpreadText;

struct InteractionOptions {
  std::string predictors = eval_common::kAllPredictors;
  int scenarios = 40;
  uint64_t seed = 1;
  std::string json_file, config_dir, recordings, model_dir, monitor = "same";
  std::string suite = "default";
  std::string robot;  // --robot: another arm; empty: the configured
  int threads = 1;
  int trace = -1;  // scenario whose runs are traced (-1: none)
  double time_limit = 20;
  bool retrain = false, quiet = false;
};

Json VectorJson(const Eigen::VectorXd& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

// The other options; prints why and returns false when one is bad.
bool CheckOptions(const InteractionOptions& o) {
  if (o.scenarios < 1) {
    std::cerr << "iplan eval interaction: --scenarios must be at least 1, got " << o.scenarios << "\n";
    return false;
  }
  if (!(o.time_limit > 0)) {
    std::cerr << "iplan eval interaction: --time-limit must be > 0 s\n";
    return false;
  }
  if (o.monitor != "same" && o.monitor != "model") {
    std::cerr << "iplan eval interaction: --monitor-prediction must be 'same' or 'model', got '" << o.monitor << "'\n";
    return false;
  }
  if (!cell_sim::ParseSuite(o.suite)) {
    std::string known;
    for (const auto& n : cell_sim::SuiteNames()) known += (known.empty() ? "'" : " or '") + n + "'";
    std::cerr << "iplan eval interaction: --suite must be " << known << ", got '" << o.suite << "'\n";
    return false;
  }
  return true;
}

// What the benchmark loads before it runs: the cell and its intent model
// (eval_common::CellInputs) and the recorded motion.
struct EvalInputs : eval_common::CellInputs {
  std::string recordings_file;
  intent::SkeletonDataset recordings;
};

// Loads the recorded motion, the cell's configuration and the intent model.
// Throws std::runtime_error.
void LoadInputs(const InteractionOptions& o, EvalInputs* in) {
  const std::string dir = eval_common::ConfigDir(o.config_dir);
  // The recorded motion sits beside the checkout (../shared, as the
  // perception replay's example path says).
  in->recordings_file =
      o.recordings.empty()
          ? (fs::path(dir) / ".." / ".." / "shared" / "data" / "assembly.csv").lexically_normal().string()
          : o.recordings;
  if (!fs::exists(in->recordings_file)) {
    throw std::runtime_error("no recorded motion at " + in->recordings_file + " (set --recordings)");
  }
  in->recordings = intent::LoadSkeletonCsv(in->recordings_file);
  eval_common::LoadCell(dir, o.robot, o.threads, o.model_dir, o.retrain, in);
}

void PrintHeader(const InteractionOptions& o, const EvalInputs& in, const cell_sim::BenchmarkSetup& setup,
                 const std::vector<Predictor>& predictors, std::size_t num_scenarios) {
  std::cout << "iplan eval interaction: " << num_scenarios << " scenarios of the " << o.suite << " suite, seed " << o.seed
            << ", predictors";
  for (Predictor p : predictors) std::cout << " " << cell_sim::ToString(p);
  std::cout << "\n  configuration " << in.dir << "\n  recorded motion " << in.recordings_file << "\n  " << in.model.summary
            << "\n  monitor prediction: "
            << (setup.monitor_input == cell_sim::MonitorInput::kModel ? "the model's, for every predictor"
                                                                        : "the planner's (with none: the model's)")
            << "; planner threads " << (o.threads > 0 ? std::to_string(o.threads) : std::string("as configured"));
  if (o.suite == cell_sim::ToString(cell_sim::Suite::kSharedSpace)) {
    std::cout << "\n  shared space: every scenario's person within " << Fixed(setup.shared_space.max_path_distance, 2)
              << " m of the straight joint path from start to goal, within " << Fixed(setup.shared_space.window, 1)
              << " s of the task command (path_distance_m per scenario in the JSON)";
  }
  std::cout << "\n  baseline covariance growth per joint, fitted on the model's training demonstrations:";
  const auto& body_joints = in.cell.body->params().joints;
  for (const auto* b : {&setup.constant_position, &setup.constant_velocity}) {
    std::cout << "\n    " << (b == &setup.constant_position ? "constant-position speed_std m/s:       "
                                                             : "constant-velocity acceleration_std m/s^2:");
    for (std::size_t j = 0; j < b->joint_growth.size(); ++j) {
      std::cout << " " << body_joints[j] << " " << Fixed(b->joint_growth[j], 3);
    }
  }
  std::cout << "\n\n";
}

// One scenario's run with one predictor, for the JSON.
Json ScenarioJson(const cell_sim::ScenarioSpec& s, Predictor predictor, const cell_sim::InteractionResult& r) {
  Json j;
  j["scenario"] = s.index;
  j["predictor"] = cell_sim::ToString(predictor);
  j["source"] = s.source;
  j["subject"] = s.subject;
  j["sequence"] = s.sequence;
  j["placement_m"] = VectorJson(s.placement_W);
  j["yaw_rad"] = s.yaw;
  if (s.source == "recorded") j["clip_start_s"] = s.clip_start;
  j["delay_s"] = s.delay;
  j["task"] = s.task;
  j["start"] = s.start;
  j["start_q"] = VectorJson(s.start_q);
  j["goal_q"] = VectorJson(s.goal_q);
  if (s.retreat_q.size() > 0) j["retreat_q"] = VectorJson(s.retreat_q);
  if (s.task == "reach") j["reach_p_m"] = VectorJson(s.reach_p_WE);
  j["noise_seed"] = s.seed;
  if (!s.kind.empty()) {
    j["kind"] = s.kind;
    j["shared_point_m"] = VectorJson(s.shared_point_W);
    if (s.path_distance) j["path_distance_m"] = *s.path_distance;
    j["draws"] = s.draws;
    for (const auto& a : s.person_actions) {
      if (a.kind == perception::MotionKind::kRest) continue;
      j["person_action"] = Json{{"name", a.name},
                                {"hand", a.kind == perception::MotionKind::kWork ? "both" : (a.right_hand ? "right" : "left")},
                                {"target_m", VectorJson(a.target_W)},
                                {"period_s", a.period}};
    }
    if (s.sweep) {
      j["sweep"] = Json{{"hand", s.sweep->right_hand ? "right" : "left"}, {"from_m", VectorJson(s.sweep->from_W)},
                        {"to_m", VectorJson(s.sweep->to_W)},         {"start_s", s.sweep->start},
                        {"approach_s", s.sweep->approach},           {"duration_s", s.sweep->duration}};
    }
  }
  j["succeeded"] = r.finished && r.status == trajopt::TaskStatus::kSucceeded;
  if (!r.reason.empty()) j["reason"] = r.reason;
  j["task_time_s"] = r.task_time;
  j["protective_stops"] = r.protective_stops;
  j["stops_by_separation"] = r.stops_separation;
  j["stops_by_bound"] = r.stops_bound;
  j["stop_time_s"] = r.stop_time;
  j["slow_downs"] = r.slow_downs;
  j["slow_time_s"] = r.slow_time;
  j["min_separation_m"] = r.min_separation;
  j["max_bound"] = r.max_bound;
  j["true_contacts"] = r.true_contacts;
  j["robot_moving_contacts"] = r.robot_moving_contacts;
  j["robot_at_rest_contacts"] = r.robot_at_rest_contacts;
  if (!r.contact_speeds.empty()) {
    Json speeds = Json::array();
    for (double v : r.contact_speeds) speeds.push_back(v);
    j["contact_robot_speeds_rad_s"] = speeds;
  }
  j["waits"] = r.waits;
  j["planner_delay_s"] = r.planner_delay;
  if (!r.first_stop_reason.empty()) j["first_stop"] = r.first_stop_reason;
  return j;
}

// One predictor's summary, for the JSON.
Json SummaryJson(const cell_sim::PredictorSummary& s) {
  Json j;
  j["scenarios"] = s.scenarios;
  j["succeeded"] = s.succeeded;
  j["task_time_s"] = SpreadJson(s.task_time);
  Json stops = SpreadJson(s.protective_stops);
  stops["total"] = s.protective_stops_total;
  stops["by_separation"] = s.stops_separation_total;
  stops["by_bound"] = s.stops_bound_total;
  j["protective_stops"] = stops;
  Json stop_time = SpreadJson(s.stop_time);
  stop_time["total"] = s.stop_time_total;
  j["stop_time_s"] = stop_time;
  j["slow_downs"] = Json{{"total", s.slow_downs_total}};
  j["slow_time_s"] = Json{{"total", s.slow_time_total}};
  j["min_separation_m"] = SpreadJson(s.min_separation);
  j["max_bound"] = SpreadJson(s.max_bound);
  j["true_contacts"] = s.true_contacts;
  j["robot_moving_contacts"] = s.robot_moving_contacts;
  j["robot_at_rest_contacts"] = s.robot_at_rest_contacts;
  if (s.has_reference) {
    j["vs_none"] = Json{{"task_time_median_ratio", RatioJson(s.task_time_median_ratio)},
                        {"task_time_paired_ratio", SpreadJson(s.task_time_ratio)},
                        {"protective_stops_ratio", RatioJson(s.protective_stops_ratio)},
                        {"stop_time_ratio", RatioJson(s.stop_time_ratio)}};
  }
  return j;
}

Json GrowthJson(const cell_sim::BenchmarkSetup& setup, const std::vector<std::string>& body_joints) {
  Json growth = Json::object();
  for (const auto* b : {&setup.constant_position, &setup.constant_velocity}) {
    Json g = Json::object();
    for (std::size_t j = 0; j < b->joint_growth.size(); ++j) g[body_joints[j]] = b->joint_growth[j];
    growth[b == &setup.constant_position ? "constant-position_speed_std_m_s" : "constant-velocity_acceleration_std_m_s2"] = g;
  }
  return growth;
}

void PrintTable(const std::vector<cell_sim::PredictorSummary>& summary) {
  const int w = 19;
  std::cout << std::left << std::setw(w) << "predictor" << std::setw(24) << "task time s" << std::setw(20)
            << "stops tot sep/bnd" << std::setw(24) << "time in stop s" << std::setw(24) << "min separation m"
            << std::setw(24) << "max true bound" << std::setw(9) << "contacts" << std::setw(8) << "moving"
            << std::setw(9) << "at rest" << "done\n";
  for (const auto& s : summary) {
    std::cout << std::left << std::setw(w) << cell_sim::ToString(s.predictor) << std::setw(24)
              << SpreadText(s.task_time, 2) << std::setw(20)
              << (std::to_string(s.protective_stops_total) + " " + std::to_string(s.stops_separation_total) + "/" +
                  std::to_string(s.stops_bound_total))
              << std::setw(24) << SpreadText(s.stop_time, 2) << std::setw(24) << SpreadText(s.min_separation, 3)
              << std::setw(24) << SpreadText(s.max_bound, 3) << std::setw(9) << s.true_contacts << std::setw(8)
              << s.robot_moving_contacts << std::setw(9) << s.robot_at_rest_contacts << s.succeeded << "/" << s.scenarios
              << "\n";
  }
  if (summary.empty() || !summary.front().has_reference) return;
  std::cout << "\npaired against none: task time (median of per-scenario ratios [p10, p90]; ratio of medians),\n"
            << "protective stops and time in stop (ratio of totals)\n";
  for (const auto& s : summary) {
    std::cout << "  " << std::left << std::setw(w) << cell_sim::ToString(s.predictor) << std::setw(24)
              << SpreadText(s.task_time_ratio, 2) << std::setw(8) << Fixed(s.task_time_median_ratio, 2)
              << " stops " << std::setw(8) << Fixed(s.protective_stops_ratio, 2) << " stop time "
              << Fixed(s.stop_time_ratio, 2) << "\n";
  }
}

// Runs every scenario with every predictor: results per scenario, the
// planning cycle times, and the scenarios' JSON. Returns false on a failure
// (printed).
bool RunScenarios(const InteractionOptions& o, const std::vector<Predictor>& predictors,
                  const std::vector<cell_sim::ScenarioSpec>& specs, cell_sim::BenchmarkSetup* setup,
                  std::vector<std::vector<cell_sim::InteractionResult>>* results, std::vector<double>* cycle_times,
                  Json* scenarios) {
  for (const auto& s : specs) {
    if (o.trace >= 0 && s.index != o.trace) continue;
    const auto t0 = std::chrono::steady_clock::now();
    if (o.trace >= 0) {
      setup->loop.trace = [](double t, const std::string& event) {
        std::cerr << "    " << std::fixed << std::setprecision(2) << std::setw(6) << t << " " << event << "\n";
      };
    }
    try {
      results->push_back(cell_sim::RunScenario(*setup, s, predictors));
    } catch (const std::exception& e) {
      std::cerr << "iplan eval interaction: scenario " << s.index << ": " << e.what() << "\n";
      return false;
    }
    const auto& row = results->back();
    if (!o.quiet) {
      std::cerr << "  scenario " << std::setw(3) << s.index + 1 << "/" << specs.size() << " "
                << (s.kind.empty() ? "" : s.kind + " ") << s.source << " " << s.sequence.substr(0, 24) << ", " << s.task
                << " from " << s.start << ":";
      for (std::size_t p = 0; p < predictors.size(); ++p) {
        std::cerr << " " << cell_sim::ToString(predictors[p]) << " " << Fixed(row[p].task_time, 1) << " s/"
                  << row[p].protective_stops << "st";
      }
      std::cerr << " (" << Fixed(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1)
                << " s)\n";
    }
    for (std::size_t p = 0; p < predictors.size(); ++p) {
      cycle_times->insert(cycle_times->end(), row[p].planning_times.begin(), row[p].planning_times.end());
      scenarios->push_back(ScenarioJson(s, predictors[p], row[p]));
    }
  }
  return true;
}

int RunInteraction(const InteractionOptions& o) {
  // Options first: a bad request is refused before anything is loaded.
  const std::optional<std::vector<Predictor>> parsed = eval_common::ParsePredictors(o.predictors, "iplan eval interaction");
  if (!parsed || !CheckOptions(o)) return 2;
  const std::vector<Predictor>& predictors = *parsed;
  if (std::find(predictors.begin(), predictors.end(), Predictor::kOracleAction) != predictors.end()) {
    std::cerr << "iplan eval interaction: the oracle-action predictor needs the person's actions; it runs in iplan "
                 "eval cell only\n";
    return 2;
  }
  const auto wall0 = std::chrono::steady_clock::now();
  EvalInputs in;
  cell_sim::BenchmarkSetup setup;
  std::vector<cell_sim::ScenarioSpec> specs;
  try {
    LoadInputs(o, &in);
    setup = in.cell.MakeSetup();
    setup.intent_model = in.intent_model;
    setup.recordings = &in.recordings;
    setup.recordings_file = in.recordings_file;
    // As perception.replay.joint_map would rename them for this body model.
    setup.joint_map = {{"wrist_l", "hand_l"}, {"wrist_r", "hand_r"}};
    setup.time_limit = o.time_limit;
    setup.loop.max_duration = o.time_limit + 1.0;
    setup.monitor_input = o.monitor == "same" ? cell_sim::MonitorInput::kSame : cell_sim::MonitorInput::kModel;
    try {
      cell_sim::CalibrateBaselines(RecordCellDemonstrations(in.cell.person), &setup);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("baseline calibration: ") + e.what());
    }
    specs = cell_sim::MakeScenarios(setup, o.scenarios, o.seed, *cell_sim::ParseSuite(o.suite));
  } catch (const std::exception& e) {
    std::cerr << "iplan eval interaction: " << e.what() << "\n";
    return 2;
  }
  PrintHeader(o, in, setup, predictors, specs.size());

  std::vector<std::vector<cell_sim::InteractionResult>> results;
  std::vector<double> cycle_times;
  Json scenarios = Json::array();
  if (!RunScenarios(o, predictors, specs, &setup, &results, &cycle_times, &scenarios)) return 1;

  const std::vector<cell_sim::PredictorSummary> summary = cell_sim::Summarize(predictors, results);
  Json per = Json::object();
  for (const auto& s : summary) per[cell_sim::ToString(s.predictor)] = SummaryJson(s);
  Json doc;
  doc["command"] = "iplan eval interaction";
  doc["seed"] = o.seed;
  doc["suite"] = o.suite;
  if (o.suite == cell_sim::ToString(cell_sim::Suite::kSharedSpace)) {
    doc["shared_space"] = Json{{"max_path_distance_m", setup.shared_space.max_path_distance},
                               {"window_s", setup.shared_space.window},
                               {"path_samples", setup.shared_space.path_samples}};
  }
  doc["num_scenarios"] = specs.size();
  doc["monitor_prediction"] = o.monitor;
  doc["time_limit_s"] = o.time_limit;
  doc["recordings"] = fs::path(in.recordings_file).filename().string();
  doc["baseline_growth"] = GrowthJson(setup, in.cell.body->params().joints);
  doc["predictors"] = std::move(per);
  doc["scenarios"] = std::move(scenarios);

  PrintTable(summary);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  std::sort(cycle_times.begin(), cycle_times.end());
  std::cout << "\nwall time " << Fixed(wall, 1) << " s; planning cycles " << cycle_times.size() << ", p50 "
            << Fixed(1e3 * core::QuantileSorted(cycle_times, 0.5), 1) << " ms, p99 "
            << Fixed(1e3 * core::QuantileSorted(cycle_times, 0.99), 1) << " ms (wall time, not in the JSON)\n";
  if (!o.json_file.empty()) {
    try {
      core::WriteFileAtomically(o.json_file, doc.dump(2) + "\n");
    } catch (const std::exception& e) {
      std::cerr << "iplan eval interaction: cannot write " << o.json_file << ": " << e.what() << "\n";
      return 1;
    }
    std::cout << "JSON written to " << o.json_file << "\n";
  }
  return 0;
}

const bool kRegistered = RegisterCommand("eval", [](CLI::App& app) {
  CLI::App* eval = app.add_subcommand("eval", "Benchmarks of the whole cell, in one process and in simulated time");
  eval->require_subcommand(1);
  auto o = std::make_shared<InteractionOptions>();
  CLI::App* c = eval->add_subcommand(
      "interaction",
      "Closed-loop interaction benchmark: seeded scenarios in the cell (a robot task from the task graph or a\n"
      "table-top reach while a person moves near or across its path: recorded arm motion of assembly.csv, both\n"
      "people, placed across the table, or the synthetic person of perception.yaml), each run through the\n"
      "services' own cores at the cell's rates (skeletons with sensor noise -> prediction -> replanner every\n"
      "planning step -> collision-risk monitor, whose PROTECTIVE_STOP stops the simulated robot, resuming after\n"
      "the supervisor's resume_delay -> robot), once per predictor. The true body decides contacts, separation\n"
      "and the true bound; a contact counts as robot-moving when the robot's fastest joint exceeds 0.01 rad/s at its\n"
      "first moment, else as robot-at-rest. Deterministic for a seed. Prints a table (median [p10, p90] over the\n"
      "scenarios and ratios against 'none'); --json writes every figure and every scenario. Exit code 2 on bad input.\n"
      "Suites: default (the above), shared-space (sharing space is the point; scenario i is of kind i % 4:\n"
      "hand-over: the hand_over task while the person reaches towards the hand-over place; parts-bin: fetch_left\n"
      "while the person reaches into the bin or their tray beside it; co-assembly: a reach to the near side of the\n"
      "person's assembly area while they assemble there; crossing: a graph task while the person's hand sweeps\n"
      "across the robot's path mid-task; the synthetic person in scenarios 0-3 of every 8, recorded motion in 4-7;\n"
      "every scenario's person comes within 0.35 m of the straight joint path from start to goal within 5 s of the\n"
      "task command, else it is drawn again).\n"
      "Predictors: none (the planner gets no prediction; only the monitor protects, with the model's), constant-position,\n"
      "constant-velocity (least-squares velocity over 0.25 s), model (the cell's trained intent model, trained\n"
      "or cached as `iplan demo --prepare-only` does), oracle (the true future with the model's covariances).");
  c->add_option("--predictors", o->predictors,
                "comma-separated predictors to compare (none, constant-position, constant-velocity, model, oracle)")
      ->capture_default_str();
  c->add_option("--scenarios", o->scenarios, "number of scenarios (>= 1)")->capture_default_str();
  c->add_option("--suite", o->suite,
                "which scenarios: 'default' (tasks and reaches, the person near or across the path) or 'shared-space' "
                "(hand-over, parts bin, co-assembly, crossing; the person always within reach of the path)")
      ->capture_default_str();
  c->add_option("--seed", o->seed, "seed of the scenarios and the sensor noise")->capture_default_str();
  c->add_option("--json", o->json_file, "write the figures and every scenario's run as JSON to this file");
  c->add_option("--config-dir", o->config_dir, "configuration folder (default: $IPLAN_CONFIG_DIR, installed, or source)");
  c->add_option("--robot", o->robot,
                "another arm instead of the configured one: a URDF or URDF overlay (docs/robots.md); the task "
                "graph's poses are solved for it")
      ->check(CLI::ExistingFile);
  c->add_option("--recordings", o->recordings,
                "skeleton CSV of recorded motion (default: CONFIG/../../shared/data/assembly.csv)");
  c->add_option("--monitor-prediction", o->monitor,
                "what the collision-risk monitor predicts with: 'same' (the planner's prediction, as the cell's one "
                "prediction topic carries it; with none the model's) or 'model' (the model's for every predictor: "
                "only planning differs)")
      ->capture_default_str();
  c->add_option("--time-limit", o->time_limit, "s a task may take before it counts as failed")->capture_default_str();
  c->add_option("--threads", o->threads,
                "planner threads (0: as planner_replanning.yaml; results do not depend on it)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  c->add_option("--model-dir", o->model_dir,
                "folder for the intent model when config/models is not writable (default: a temporary folder)");
  c->add_flag("--retrain", o->retrain, "train the intent model again even if a cached one fits");
  c->add_flag("--quiet", o->quiet, "no progress line per scenario on stderr");
  c->add_option("--trace", o->trace,
                "run only scenario N (0-based) and print every planning cycle, stop and resume of each predictor's run "
                "to stderr, to see why it went as it did");
  c->callback([o] { SetExitCode(RunInteraction(*o)); });
  AddEvalCellCommand(eval);
});

}  // namespace
}  // namespace iplan::cli
