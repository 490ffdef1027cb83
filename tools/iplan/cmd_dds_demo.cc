// iplan demo: the working cell. Starts every service as a separate process on
// loopback DDS (perception with the synthetic person, intent, collision risk,
// trajectory optimisation, the robot simulator and the supervisor), runs
// collaborative episodes of the task graph, shows live progress, and prints a
// summary (also as JSON with --summary): tasks, completion and waiting times,
// separation, collision bound, protective stops, true contacts, end-to-end
// latency and the learning curve over episodes.
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "services/collision_risk/risk_config.h"
#include "services/supervisor/core/supervisor_settings.h"
#include "services/supervisor/core/task_goals.h"
#include "services/supervisor/core/task_planner.h"
#include "services/trajopt/trajopt_config.h"
#include "dds_cell_model.h"
#include "dds_common.h"
#include "dds_demo_security.h"
#include "dds_viewer_common.h"
#include "demo_monitor.h"
#include "iplan/core/process.h"
#include "iplan/core/stats.h"
#include "iplan/framework/config.h"
#include "iplan/framework/node.h"
#include "iplan/framework/service.h"
#include "iplan/framework/service_file.h"

namespace iplan::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

volatile sig_atomic_t g_stop = 0;

struct DemoOptions {
  std::string vendor;
  bool mixed = false;
  int domain = -1;
  int episodes = 6;
  double timeout = 170;
  std::string summary_file, config_dir, state_dir;
  std::string record_file;  ///< MCAP recording of the run (iplan record); empty: none
  bool keep_learning = false, retrain = false, prepare_only = false, insecure = false;
  std::string security;  ///< --security DIR (dds_demo_security.h)
  /// What the planner and monitor are given as the prediction: model,
  /// constant-position, constant-velocity (intent.predictor), or none (the
  /// planner ignores the person, trajopt.use_prediction false; collision
  /// risk still gets the model's prediction).
  std::string predictor = "model";
  /// "skeleton": the skeleton stream only; "depth": also the simulated depth
  /// camera (perception) and the cloud service; "depth-only": the camera
  /// and the cloud service instead of the skeleton (no skeleton, no intent:
  /// trajopt and collision risk work from the cloud's outputs alone).
  std::string sensor = "skeleton";
  /// Another arm for the whole cell (docs/robots.md); empty: the configured.
  std::string robot;
};

// The services in start order (executable suffix, config name).
const std::vector<std::pair<std::string, std::string>> kServices = {
    {"robot-sim", "robot_sim"},           {"perception", "perception"}, {"intent", "intent"},
    {"collision-risk", "collision_risk"}, {"trajopt", "trajopt"},       {"supervisor", "supervisor"}};
// --sensor depth adds the cloud service (after perception, its source);
// depth-only also drops intent (there is no skeleton to predict from).
const std::pair<std::string, std::string> kCloudService = {"cloud", "cloud"};
// What the supervisor watches in a camera-only cell: the depth camera's
// person instead of the skeleton and its prediction.
const char* const kDepthOnlyWatch = "[human_points, joint_states, robot_trajectory, collision_risk]";
// A camera-only cell judges the person's points at their measured speed plus
// this many standard deviations of it (collision risk's and trajopt's
// human_points; the services' own default is no measured speed at all, and 2
// sigma when switched on). At 2 sigma a still person's parts get about
// 0.5 m/s (S_p about 0.38 m at rest) and the demo's hand-over never
// completes; at 1 sigma 0.23 m/s, 83 % of the truly moving points' speeds
// covered against 96 % at 2 (docs/perception-clouds.md, "The camera-only
// cell").
const char* const kDepthOnlySpeedSigmas = "1";
// s; its --timeout unless given (the default 170 s fits the skeleton cell).
constexpr double kDepthOnlyTimeout = 480;

// One run of the demo: the processes, their vendors and what came of it.
class DemoRun {
 public:
  explicit DemoRun(const DemoOptions& o)
      : o_(o),
        vendor_a_(o.vendor.empty() ? dds::DefaultVendor() : dds::ParseVendor(o.vendor)),
        vendor_b_(vendor_a_ == dds::Vendor::kCyclone ? dds::Vendor::kFastDds : dds::Vendor::kCyclone),
        // A domain of its own so that the demo never talks to a running cell.
        domain_(o.domain >= 0 ? o.domain : 100 + static_cast<int>(getpid() % 100)),
        config_dir_(o.config_dir.empty() ? framework::DefaultConfigDir() : o.config_dir) {}

  int Run() {
    if (const std::optional<int> rc = Prepare()) return *rc;
    if (const std::optional<int> rc = StartServices()) return *rc;
    auto participant = dds::Participant::Create(security_->Participant(vendor_a_, domain_, "iplan-demo"));
    spdlog::set_level(spdlog::level::warn);  // the progress lines say what matters
    framework::NodeOptions nopts;
    nopts.diagnostics_period = 0;
    framework::Node node("demo", *participant, nopts);
    CellMonitor mon(node, static_cast<int>(graph_.tasks.size()), t0_);
    if (judge_) mon.AuditStops(node, std::move(judge_));
    Watch(node, mon);
    Stop(node, mon);
    const double contacts = mon.DiagNumber("robot_sim", "true_contacts", -1);
    PrintSummary(mon, contacts);
    if (!o_.summary_file.empty()) WriteSummary(mon, contacts);
    if (!failure_.empty()) {
      std::cerr << "\niplan demo: " << failure_ << "\n";
      return 1;
    }
    if (contacts != 0) {
      std::cerr << "\niplan demo: the robot touched the person (" << contacts << " true contacts)\n";
      return 1;
    }
    std::cout << std::flush;
    return 0;
  }

 private:
  // --mixed: perception, collision risk and the supervisor on one vendor,
  // intent, trajectory optimisation and the simulator on the other.
  dds::Vendor VendorOf(const std::string& name) const {
    return o_.mixed && (name == "intent" || name == "trajopt" || name == "robot_sim") ? vendor_b_ : vendor_a_;
  }
  std::string Cfg(const std::string& name) const { return (fs::path(config_dir_) / (name + ".yaml")).string(); }

  // The state folder, the intent model (trained from the synthetic person's
  // demonstrations once) and the task graph; an exit code when the run ends here.
  std::optional<int> Prepare() {
    if (config_dir_.empty()) {
      std::cerr << "iplan demo: no configuration found (set --config-dir or $IPLAN_CONFIG_DIR)\n";
      return 2;
    }
    state_dir_ = o_.state_dir;
    if (state_dir_.empty()) {
      std::string tmpl = (fs::temp_directory_path() / "iplan-demo-XXXXXX").string();
      if (!mkdtemp(tmpl.data())) {
        std::cerr << "iplan demo: cannot create a state folder in " << fs::temp_directory_path() << "\n";
        return 1;
      }
      state_dir_ = tmpl;
    }
    fs::create_directories(state_dir_);
    std::cout << "iplan demo: the collaborative cell on loopback DDS, domain " << domain_ << "\n"
              << "  configuration " << config_dir_ << "\n  state and service logs (<service>.err) " << state_dir_ << "\n";
    if (o_.predictor != "model") std::cout << "  predictor: " << o_.predictor << " (ablation)\n";
    if (o_.sensor == "depth-only") {
      std::cout << "  sensor: depth camera only (no skeleton, no intent; the planner and collision risk work from "
                   "the cloud service's boxes and human points, at their measured speed + "
                << kDepthOnlySpeedSigmas << " sigma: docs/perception-clouds.md)\n";
      if (o_.predictor != "model" && o_.predictor != "none") {
        std::cerr << "iplan demo: --predictor " << o_.predictor
                  << " predicts from skeletons; --sensor depth-only has none (model or none)\n";
        return 2;
      }
    }
    const std::string view_args = o_.robot.empty() ? "" : " --robot " + fs::absolute(o_.robot).string();
    if (!o_.prepare_only && !(security_ = SecureDemoOrExplain(o_.insecure, o_.security, o_.mixed, domain_, view_args)))
      return 2;
    try {
      if (!fs::exists(fs::path(config_dir_) / "intent.yaml")) throw std::runtime_error("no intent.yaml in " + config_dir_);
      if (o_.sensor != "depth-only" || o_.prepare_only) {  // a camera-only cell runs no intent service
        std::cout << "  intent model: checking ..." << std::flush;
        model_ = EnsureCellModel(Cfg("perception"), Cfg("intent"), state_dir_, o_.retrain);
        std::cout << "\r  " << model_.summary << "\n";
      }
      if (o_.prepare_only) {
        std::cout << "  model path: " << model_.path << "\n";
        return 0;
      }
      framework::ServiceFile sup(Cfg("supervisor"));
      supervisor::SupervisorSettings supervisor;
      sup.ReadSection("supervisor", &supervisor).Finish();  // as the supervisor reads it
      graph_ = supervisor::LoadTaskGraph(sup.ResolvePath(supervisor.task_graph));
      resume_delay_ = supervisor.resume_delay;
      if (!o_.robot.empty()) PrepareRobot();
      judge_ = MakeStopJudge();
    } catch (const std::exception& e) {
      std::cerr << "\niplan demo: " << e.what() << "\n";
      return 2;
    }
    return std::nullopt;
  }

  // --robot: every service's robot, and the simulated robot's start at the
  // task graph's rest place solved for that arm (as the supervisor will).
  void PrepareRobot() {
    robot_file_ = fs::absolute(o_.robot).string();
    const std::unique_ptr<planning::Planner> planner = trajopt::MakePlanner(trajopt::LoadTrajoptConfig(Cfg("trajopt"), robot_file_));
    supervisor::TaskGraph graph = graph_;
    for (const std::string& note : supervisor::ResolveTaskGoals(*planner, &graph)) std::cout << "  " << note << "\n";
    const std::vector<double> rest = supervisor::RestPositions(graph);
    if (rest.empty()) throw std::runtime_error("--robot: the task graph names no rest task (key 'rest'): where would the robot start?");
    std::ostringstream q;
    q << "[";
    for (std::size_t i = 0; i < rest.size(); ++i) q << (i ? ", " : "") << std::setprecision(17) << rest[i];
    q << "]";
    rest_text_ = q.str();
    std::cout << "  robot " << planner->robot().name << " (" << robot_file_ << ", " << planner->robot().nq
              << " joints), resting at " << rest_text_ << " rad\n";
  }

  // The collision-risk monitor's rule, as configured, for the true person
  // (stop_audit.h); null, with a note, when it cannot be built.
  std::unique_ptr<TrueSeparationJudge> MakeStopJudge() const {
    try {
      const collision_risk::RiskConfig c = collision_risk::LoadRiskConfig(Cfg("collision_risk"), robot_file_);
      return std::make_unique<TrueSeparationJudge>(collision::LoadRobotModel(c.robot_file),
                                                   collision::LoadHumanBodyParams(c.human_body_file), c.params);
    } catch (const std::exception& e) {
      std::cout << "  stops not audited against the true person: " << e.what() << "\n";
      return nullptr;
    }
  }

  std::vector<std::string> ServiceArguments(const std::string& exe, const std::string& name) const {
    std::vector<std::string> argv = {core::ExecutableDir() + "/iplan-" + exe, "--config", Cfg(name), "--dds",
                                     dds::ToString(VendorOf(name)), "--domain", std::to_string(domain_)};
    argv.insert(argv.end(), security_->service_args.begin(), security_->service_args.end());
    if (name == "intent") argv.insert(argv.end(), {"--set", "intent.model=" + model_.path});
    if (name == "intent" && o_.predictor != "model" && o_.predictor != "none") {
      argv.insert(argv.end(), {"--set", "intent.predictor=" + o_.predictor});
    }
    if (name == "trajopt" && o_.predictor == "none") argv.insert(argv.end(), {"--set", "trajopt.use_prediction=false"});
    if (name == "perception") argv.insert(argv.end(), {"--set", "perception.provider=synthetic", "--set",
                                                       "perception.publish_truth=true"});
    if (name == "perception" && o_.sensor != "skeleton") {
      argv.insert(argv.end(), {"--set", "perception.depth.provider=simulated"});
    }
    if (name == "perception" && o_.sensor == "depth-only") {
      argv.insert(argv.end(), {"--set", "perception.publish_skeleton=false"});
    }
    if (name == "supervisor" && o_.sensor == "depth-only") {
      argv.insert(argv.end(), {"--set", std::string("supervisor.watch=") + kDepthOnlyWatch});
    }
    if ((name == "collision_risk" || name == "trajopt") && o_.sensor == "depth-only") {
      // The points' measured speeds (kDepthOnlySpeedSigmas, header comment).
      argv.insert(argv.end(), {"--set", name + ".human_points.tracked_speeds=true", "--set",
                               name + ".human_points.speed_sigmas=" + kDepthOnlySpeedSigmas});
    }
    if (!robot_file_.empty()) {
      if (name == "perception") argv.insert(argv.end(), {"--set", "perception.depth.simulated.robot=" + robot_file_});
      else if (name != "intent") argv.insert(argv.end(), {"--set", name + ".robot=" + robot_file_});
      if (name == "robot_sim") argv.insert(argv.end(), {"--set", "robot_sim.initial_positions=" + rest_text_});
    }
    if (name == "supervisor") {
      argv.insert(argv.end(), {"--set", "supervisor.max_episodes=" + std::to_string(o_.episodes)});
      if (!o_.keep_learning) argv.insert(argv.end(), {"--set", "supervisor.q_table=" + state_dir_ + "/q_table.bin"});
    }
    return argv;
  }

  // The recorder first, so that it hears every service from its first
  // message, then every service; an exit code when one cannot start.
  std::optional<int> StartServices() {
    if (!o_.record_file.empty()) {
      try {
        recorder_ = StartRecorder(dds::ToString(vendor_a_), domain_, o_.record_file, config_dir_, state_dir_ + "/record", security_->env);
        std::cout << "  recording to " << o_.record_file << "\n";
      } catch (const std::exception& e) {
        std::cerr << "iplan demo: " << e.what() << "\n";
        return 1;
      }
    }
    t0_ = Clock::now();
    std::cout << "  services:";
    services_ = kServices;
    if (o_.sensor != "skeleton") services_.insert(services_.begin() + 2, kCloudService);
    if (o_.sensor == "depth-only") {
      services_.erase(std::remove_if(services_.begin(), services_.end(), [](const auto& s) { return s.second == "intent"; }),
                      services_.end());
    }
    for (const auto& [exe, name] : services_) {
      try {
        procs_.push_back(std::make_unique<core::Process>(ServiceArguments(exe, name), security_->env, false,
                                                         state_dir_ + "/" + name));
      } catch (const std::exception& e) {
        std::cerr << "\niplan demo: cannot start iplan-" << exe << ": " << e.what() << "\n";
        return 1;
      }
      names_.push_back(name);
      std::cout << " " << name << " (" << dds::ToString(VendorOf(name)) << ")";
    }
    std::cout << "\n  episodes: " << o_.episodes << " of " << graph_.tasks.size() << " robot tasks; Q-table "
              << (o_.keep_learning ? "from the configuration (keeps learning)" : "fresh (learns from scratch)") << "\n"
              << std::endl;
    return std::nullopt;
  }

  // Progress until every episode is done, a service exits, the time limit
  // or a signal.
  void Watch(framework::Node& node, CellMonitor& mon) {
    g_stop = 0;
    signal(SIGINT, [](int) { g_stop = 1; });
    signal(SIGTERM, [](int) { g_stop = 1; });
    auto next_report = Clock::now() + 2s;
    while (!g_stop) {
      node.SpinOnce(50ms);
      for (const auto& e : mon.TakeEvents()) std::cout << "  [" << std::setw(4) << Fixed(mon.Now(), 0) << " s] " << e << std::endl;
      if (mon.completed_episodes() >= o_.episodes) break;
      for (size_t i = 0; i < procs_.size() && failure_.empty(); ++i) {
        if (!procs_[i]->Running()) failure_ = "iplan-" + services_[i].first + " exited unexpectedly:\n" + Tail(procs_[i]->Stderr(), 15);
      }
      if (!failure_.empty()) break;
      if (mon.Now() > o_.timeout) {
        failure_ = "time limit of " + Fixed(o_.timeout, 0) + " s reached";
        break;
      }
      if (Clock::now() >= next_report) {
        next_report += 2s;
        std::cout << mon.Progress(o_.episodes) << std::endl;
      }
    }
    if (g_stop && failure_.empty()) failure_ = "interrupted";
  }

  // Lets the last diagnostics arrive, then stops every service and the recorder.
  void Stop(framework::Node& node, CellMonitor& mon) {
    for (int k = 0; k < 25; ++k) node.SpinOnce(40ms);
    elapsed_ = mon.Now();
    for (auto& p : procs_) p->Signal(SIGTERM);
    for (size_t i = 0; i < procs_.size(); ++i) {
      const auto rc = procs_[i]->Wait(10s);
      exit_codes_.push_back(rc ? *rc : -1);
      if (rc && *rc != 0 && failure_.empty()) failure_ = "iplan-" + services_[i].first + " exited with " + std::to_string(*rc);
    }
    if (recorder_) {
      if (auto err = StopRecorder(*recorder_); err && failure_.empty()) failure_ = *err;
    }
  }

  // The completed episodes and the robot's waiting time over all (s).
  static std::pair<std::vector<const Episode*>, double> Tally(const CellMonitor& mon) {
    std::vector<const Episode*> done;
    double waiting_total = 0;
    for (const auto& [n, e] : mon.episodes()) {
      waiting_total += e.waiting;
      if (e.done) done.push_back(&e);
    }
    return {done, waiting_total};
  }

  void PrintSummary(const CellMonitor& mon, double contacts) const {
    const auto lat = core::Summarize(mon.latency_ms_);
    const double min_true_sep = mon.DiagNumber("robot_sim", "min_true_separation_m", -1);
    const auto [done, waiting_total] = Tally(mon);
    std::cout << "\nSummary (" << Fixed(elapsed_, 0) << " s)\n"
              << "  episodes completed            " << done.size() << " / " << o_.episodes << "\n"
              << "  tasks completed               " << mon.tally().succeeded_tasks()
              << " (failed or cancelled: " << mon.tally().failed_tasks() << "; outcomes repeated, counted once: "
              << mon.tally().repeated_outcomes() << ")\n";
    if (!done.empty()) {
      std::vector<double> times;
      for (const auto* e : done) times.push_back(e->completion());
      const auto s = core::Summarize(times);
      std::cout << "  completion time per episode   mean " << Fixed(s.mean, 1) << " s (min " << Fixed(s.min, 1) << ", max "
                << Fixed(s.max, 1) << "); first " << Fixed(times.front(), 1) << " s, last " << Fixed(times.back(), 1)
                << " s\n";
    }
    std::cout << "  robot waiting time            " << Fixed(waiting_total, 1) << " s in total\n"
              << "  minimum separation            " << (min_true_sep >= 0 ? Fixed(min_true_sep, 3) + " m (true body)" : "-")
              << (mon.min_observed_separation_ < 1e9 ? ", " + Fixed(mon.min_observed_separation_, 3) + " m (observed)" : "")
              << "\n"
              << "  maximum collision bound       " << Fixed(mon.max_bound_, 4) << " (executing trajectory), "
              << Fixed(mon.max_plan_bound_, 4) << " (plans)\n"
              << "  protective stops              " << mon.stops_ << " (" << Fixed(mon.stop_time_s_, 1) << " s, resume delays "
              << "included; the first is the safe start); slowed down instead " << mon.slow_downs_ << " times (robot slowed "
              << Fixed(mon.DiagNumber("robot_sim", "slowed_down_s", 0), 1) << " s, ISO/TS 15066 speed reduction)\n"
              << "  security                      " << security_->summary << "\n"
              << "  true contacts                 " << (contacts >= 0 ? Fixed(contacts, 0) : "unknown") << "\n"
              << "  end-to-end latency            p50 " << Fixed(lat.p50, 1) << " ms, p99 " << Fixed(lat.p99, 1)
              << " ms, max " << Fixed(lat.max, 1) << " ms (" << lat.count << " trajectories; "
              << (o_.sensor == "depth-only" ? "cloud" : "skeleton") << " stamp to trajectory)\n";
    const auto intent_lat = core::Summarize(mon.intent_ms_), queue_lat = core::Summarize(mon.queue_ms_),
               planning_lat = core::Summarize(mon.planning_ms_);
    std::cout << "    stages p50/p99: " << (o_.sensor == "depth-only" ? "cloud to trajopt " : "intent ")
              << Fixed(intent_lat.p50, 1) << "/" << Fixed(intent_lat.p99, 1)
              << " ms, prediction to planning " << Fixed(queue_lat.p50, 1) << "/" << Fixed(queue_lat.p99, 1)
              << " ms, planning " << Fixed(planning_lat.p50, 1) << "/" << Fixed(planning_lat.p99, 1) << " ms\n";
    if (o_.sensor != "skeleton") {
      std::cout << "  depth path                    " << Fixed(mon.DiagNumber("cloud", "clouds", 0), 0)
                << " clouds processed (p50 " << Fixed(1e3 * mon.DiagNumber("cloud", "cycle_time_p50_s", 0), 1) << " ms, p99 "
                << Fixed(1e3 * mon.DiagNumber("cloud", "cycle_time_p99_s", 0), 1) << " ms per cloud), last: "
                << Fixed(mon.DiagNumber("cloud", "obstacles", 0), 0) << " static obstacles, "
                << Fixed(mon.DiagNumber("cloud", "human_points", 0), 0) << " human points ("
                << Fixed(mon.DiagNumber("cloud", "tracked_human_points", 0), 0) << " tracked, "
                << Fixed(mon.DiagNumber("cloud", "motions", 0), 0) << " moving parts); "
                << Fixed(mon.DiagNumber("cloud", "clouds_without_self_filter", 0), 0) << " clouds without self-filter\n";
    }
    PrintStops(mon);
    std::cout << "\nLearning curve (completion time per episode)\n  episode  time_s  waiting_s  task order\n";
    for (const auto& [n, e] : mon.episodes()) {
      std::cout << "  " << std::setw(7) << n << "  " << std::setw(6) << (e.done ? Fixed(e.completion(), 1) : "-") << "  "
                << std::setw(9) << Fixed(e.waiting, 1) << " ";
      for (const auto& t : e.order) std::cout << " " << t;
      std::cout << (e.done ? "" : " (incomplete)") << "\n";
    }
  }

  // Each stop, with the audit's timing against the true person.
  void PrintStops(const CellMonitor& mon) const {
    const StopAudit& audit = mon.stop_audit();
    const bool audited = mon.auditing_stops() && audit.judgements() > 0;
    if (mon.auditing_stops()) {
      std::cout << "  stops against the true person "
                << (audited ? Describe(Summarize(audit, mon.first_task_s(), resume_delay_))
                            : "not audited (no true pose of the person came)")
                << "\n";
    }
    for (std::size_t i = 0; i < mon.stop_reasons_.size(); ++i) {
      const bool timed = audited && i < audit.stops().size();
      std::cout << "    stop: " << (timed ? Describe(audit.stops()[i]) + " " : "") << mon.stop_reasons_[i] << "\n";
    }
  }

  static nlohmann::json StopAuditJson(const CellMonitor& mon, double resume_delay) {
    const StopAudit& audit = mon.stop_audit();
    if (!mon.auditing_stops() || audit.judgements() == 0) return nullptr;
    const StopAuditSummary a = Summarize(audit, mon.first_task_s(), resume_delay);
    nlohmann::json j = {{"judgements", audit.judgements()},
                        {"since_s", mon.first_task_s()},
                        {"stops", a.stops},
                        {"with_person_within_sp", a.with_person_within},
                        {"outlasting_resume_delay", a.outlasting},
                        {"resume_delay_s", resume_delay},
                        {"outlast_s", {{"p50", a.outlast_p50_s}, {"max", a.outlast_max_s}}},
                        {"after_s", {{"max", a.after_max_s}}},
                        {"unstopped_within_sp_s", {{"total", a.unstopped_inside_s}, {"longest", a.longest_unstopped_inside_s}}},
                        {"each", nlohmann::json::array()}};
    for (const AuditedStop& s : audit.stops()) {
      j["each"].push_back({{"start_s", s.start_s},
                           {"duration_s", s.Duration()},
                           {"person_within_sp_s", s.true_inside_s},
                           {"outlast_s", s.Outlast()},
                           {"after_s", s.After()},
                           {"reason", s.reason}});
    }
    return j;
  }

  void WriteSummary(const CellMonitor& mon, double contacts) const {
    const auto lat = core::Summarize(mon.latency_ms_);
    const auto intent_lat = core::Summarize(mon.intent_ms_), queue_lat = core::Summarize(mon.queue_ms_),
               planning_lat = core::Summarize(mon.planning_ms_);
    const double min_true_sep = mon.DiagNumber("robot_sim", "min_true_separation_m", -1);
    const auto [done, waiting_total] = Tally(mon);
    nlohmann::json j;
    j["domain"] = domain_;
    j["predictor"] = o_.predictor;
    j["sensor"] = o_.sensor;
    j["vendors"] = nlohmann::json::object();
    for (const std::string& name : names_) j["vendors"][name] = dds::ToString(VendorOf(name));
    j["monitor_vendor"] = dds::ToString(vendor_a_);
    j["duration_s"] = elapsed_;
    j["episodes_requested"] = o_.episodes;
    j["episodes_completed"] = done.size();
    j["tasks_completed"] = mon.tally().succeeded_tasks();
    j["tasks_failed_or_cancelled"] = mon.tally().failed_tasks();
    j["task_outcomes_repeated"] = mon.tally().repeated_outcomes();
    j["robot_waiting_time_s"] = waiting_total;
    j["min_separation_m"] = min_true_sep;
    j["min_observed_separation_m"] = mon.min_observed_separation_ < 1e9 ? mon.min_observed_separation_ : -1.0;
    j["max_collision_bound"] = mon.max_bound_;
    j["max_plan_collision_bound"] = mon.max_plan_bound_;
    j["protective_stops"] = mon.stops_;
    j["protective_stop_time_s"] = mon.stop_time_s_;
    j["stop_audit"] = StopAuditJson(mon, resume_delay_);
    j["slow_downs"] = {{"count", mon.slow_downs_}, {"robot_slowed_s", mon.DiagNumber("robot_sim", "slowed_down_s", 0)}};
    j["security"] = {{"secured", security_->secured}, {"keystore", security_->keystore}, {"summary", security_->summary}};
    j["true_contacts"] = contacts;
    j["latency_ms"] = {{"p50", lat.p50}, {"p99", lat.p99}, {"max", lat.max}, {"count", lat.count}};
    j["latency_stages_ms"] = {{"intent", {{"p50", intent_lat.p50}, {"p99", intent_lat.p99}}},
                              {"prediction_to_planning", {{"p50", queue_lat.p50}, {"p99", queue_lat.p99}}},
                              {"planning", {{"p50", planning_lat.p50}, {"p99", planning_lat.p99}}}};
    j["learning_curve"] = nlohmann::json::array();
    for (const auto& [n, e] : mon.episodes()) {
      j["learning_curve"].push_back({{"episode", n},
                                     {"completion_time_s", e.done ? e.completion() : -1.0},
                                     {"waiting_time_s", e.waiting},
                                     {"tasks_completed", e.succeeded},
                                     {"order", e.order}});
    }
    j["intent_model"] = {{"path", model_.path}, {"trained_now", model_.trained}, {"training_s", model_.seconds}};
    j["service_exit_codes"] = exit_codes_;
    j["failure"] = failure_;
    if (!o_.record_file.empty()) j["recording"] = fs::absolute(o_.record_file).string();
    std::ofstream(o_.summary_file) << j.dump(2) << "\n";
    std::cout << "\nsummary written to " << o_.summary_file << "\n";
    const std::string report = (fs::path(o_.summary_file).parent_path() / fs::path(o_.summary_file).stem()).string() + ".html";
    if (auto err = WriteReport(o_.summary_file, o_.record_file, report)) std::cerr << "iplan demo: no report: " << *err << "\n";
    else std::cout << "report written to " << report << " (iplan report " << o_.summary_file << ")\n";
  }

  const DemoOptions& o_;
  const dds::Vendor vendor_a_, vendor_b_;
  const int domain_;
  const std::string config_dir_;
  std::string state_dir_;
  CellModelResult model_;
  std::optional<DemoSecurity> security_;  // decided in Prepare (not for --prepare-only)
  supervisor::TaskGraph graph_;
  std::string robot_file_;  ///< --robot, absolute; empty: the configured robot
  double resume_delay_ = 0;  ///< s, the supervisor's (the stop audit's allowance)
  std::unique_ptr<TrueSeparationJudge> judge_;  ///< until the monitor takes it
  std::string rest_text_;   ///< its rest joint positions, as a YAML list
  std::unique_ptr<core::Process> recorder_;
  Clock::time_point t0_;
  std::vector<std::unique_ptr<core::Process>> procs_;
  std::vector<std::pair<std::string, std::string>> services_;  // (executable suffix, config name), in start order
  std::vector<std::string> names_;
  std::vector<int> exit_codes_;
  std::string failure_;
  double elapsed_ = 0;
};

int RunDemo(const DemoOptions& o) { return DemoRun(o).Run(); }

void Register(CLI::App& app) {
  static DemoOptions o;
  auto* d = app.add_subcommand(
      "demo",
      "Run the collaborative cell: every service as a separate process on loopback DDS (secured with DDS Security "
      "unless --insecure), the synthetic person across the table, the robot learning its task order; live "
      "progress and a summary");
  d->add_option("--dds", o.vendor, "DDS vendor of the services: cyclonedds or fastdds (default: $IPLAN_DDS, else cyclonedds)");
  d->add_flag("--mixed", o.mixed, "run half the services on each vendor (intent, trajopt and robot_sim on the other "
                                 "one); only with --insecure: secured, Debian's two vendors fail to authenticate");
  d->add_option("--episodes", o.episodes, "collaborative episodes to run")->capture_default_str()->check(CLI::Range(1, 1000));
  CLI::Option* timeout =
      d->add_option("--timeout", o.timeout, "give up after this many seconds (--sensor depth-only: 480 unless given)")
          ->capture_default_str()
          ->check(CLI::PositiveNumber);
  d->add_option("--domain", o.domain, "DDS domain (default: 100 + pid % 100, to stay apart from a running cell)")
      ->check(CLI::Range(0, 232));
  d->add_option("--summary", o.summary_file, "write the summary as JSON to this file, and its HTML report beside it");
  d->add_option("--record", o.record_file, "record the run's topics to this MCAP file (iplan record; replay: iplan view --replay)");
  d->add_option("--config-dir", o.config_dir, "configuration folder (default: $IPLAN_CONFIG_DIR, installed, or source)");
  d->add_option("--state-dir", o.state_dir, "folder for the Q-table and a fallback model (default: a new temporary folder)");
  d->add_flag("--keep-learning", o.keep_learning,
              "use the Q-table of supervisor.yaml (learning carries over between runs) instead of a fresh one");
  d->add_flag("--retrain", o.retrain, "train the intent model again even if a cached one fits");
  AddDemoSecurityOptions(d, &o.insecure, &o.security);
  d->add_option("--sensor", o.sensor,
                 "skeleton: the skeleton stream; depth: also the simulated depth camera and the cloud service "
                 "(obstacles and human points, docs/perception-clouds.md); depth-only: the camera and the cloud "
                 "service alone, no skeleton anywhere (no intent; planner and collision risk on the cloud's outputs, the "
                 "points at their measured speed + " + std::string(kDepthOnlySpeedSigmas) + " sigma)")
      ->capture_default_str()
      ->check(CLI::IsMember({"skeleton", "depth", "depth-only"}));
  d->add_option("--robot", o.robot,
                 "run the whole cell with another arm: a URDF (collision meshes are covered by spheres) or a "
                 "URDF overlay, mounted where the configured robot stands; task poses are solved for it "
                 "(docs/robots.md)")
      ->check(CLI::ExistingFile);
  d->add_option("--predictor", o.predictor,
                 "prediction the cell plans with: model (the trained intent model), constant-velocity or "
                 "constant-position (kinematic baselines from the intent service), none (the planner ignores "
                 "the person; only collision risk protects)")
      ->check(CLI::IsMember({"model", "constant-velocity", "constant-position", "none"}))
      ->capture_default_str();
  d->add_flag("--prepare-only", o.prepare_only,
              "train (or check) the cell's intent model, print its path ('model path: FILE') and exit without running the cell");
  d->callback([timeout] {
    // The camera-only cell works at the person's measured speeds and is
    // about twice as slow (docs/perception-clouds.md, "The camera-only cell").
    if (o.sensor == "depth-only" && timeout->count() == 0) o.timeout = kDepthOnlyTimeout;
    SetExitCode(RunDemo(o));
  });
}

const bool kRegistered = RegisterCommand("10-demo", Register);

}  // namespace
}  // namespace iplan::cli
