// Cost per added person (issue 17, more people): the services' cores with
// 1, 2 and 4 synthetic people in the demo cell (config/, its trained intent
// model config/models/cell_intent.model: `iplan demo --prepare-only` writes
// it). Person 1 is the configured one (torso 1.30 m across the table); the
// others stand beside them along the table's edge (y = -0.6, +0.6, -1.2 m),
// each with their own seed. Three costs, each timed per call with the wall
// process CPU time and the wall clock, in the same run:
//   BM_Intent/N        one sensor period: IntentEstimator::Update for each of
//                      the N bodies' frames (30 Hz)
//   BM_RiskEvaluate/N  RiskMonitor::Evaluate with N skeletons and N fresh
//                      predictions, along a 2 s executing trajectory
//   BM_ReplanCycle/N   Replanner::Cycle against N fresh predictions, the
//                      cell's tasks one after the other, 0.1 s steps of
//                      simulated time (one planner thread: the cost, not
//                      the parallelism)
// Counters per call: cpu_p50_us, cpu_p90_us, cpu_max_us, wall_p50_us,
// wall_p90_us, and per_person_cpu_us (cpu p50 / N).
//
//   build/bench/people_bench [--benchmark_min_time=2] [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <time.h>

#include <chrono>
#include <stdexcept>

#include "tools/cell_sim/cell_config.h"
#include "tools/cell_sim/core/interaction_benchmark.h"
#include "services/perception/core/synthetic_person.h"
#include "iplan/cell/joint_trajectory.h"
#include "iplan/core/stats.h"
#include "iplan/intent/model_io.h"

namespace iplan::cell_sim {
namespace {

constexpr int kMaxPeople = 4;
constexpr double kRate = 30;       // Hz, sensor
constexpr int kFrames = 30 * 20;   // 20 s of each person

struct Scene {
  CellConfig cell;
  std::shared_ptr<const intent::IntentModel> model;
  std::vector<std::string> joints;                            // the model's joints
  std::vector<std::vector<std::vector<intent_service::JointObservation>>> frames;  // [body][frame]
  std::vector<std::vector<collision::JointMixture>> predictions;  // [body][frame], t0 = frame / kRate
};

std::vector<intent_service::JointObservation> ToObservation(const std::vector<perception::JointSample>& s) {
  std::vector<intent_service::JointObservation> out;
  for (const auto& j : s) out.push_back({j.name, j.position_W});
  return out;
}

const Scene& GetScene() {
  static const Scene scene = [] {
    Scene s;
    const std::string dir = std::string(IPLAN_SOURCE_DIR) + "/config";
    s.cell = LoadCellConfig(dir, 1);
    const std::string model = dir + "/models/cell_intent.model";
    try {
      s.model = std::make_shared<const intent::IntentModel>(intent::LoadIntentModel(model));
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string(e.what()) + " (run `build/bin/iplan demo --prepare-only` to train it)");
    }
    s.joints = s.model->config.joints.joints;
    const double offsets[kMaxPeople] = {0.0, -0.6, 0.6, -1.2};
    for (int b = 0; b < kMaxPeople; ++b) {
      perception::SyntheticPersonParams p = s.cell.person;
      p.loop = true;
      p.torso_W.y() += offsets[b];
      p.seed += static_cast<uint64_t>(b);
      perception::SyntheticPerson person(p);
      intent_service::IntentEstimator estimator(s.model, s.cell.estimator);
      collision::JointMixture mixture;
      s.frames.emplace_back();
      s.predictions.emplace_back();
      for (int f = 0; f < kFrames; ++f) {
        intent_service::SkeletonFrame frame{1, f / kRate, ToObservation(person.Observe(f / kRate))};
        s.frames.back().push_back(frame.joints);
        if (!estimator.Update(frame, &mixture).accepted()) throw std::runtime_error("synthetic frame rejected");
        s.predictions.back().push_back(Stamped(mixture, s.joints, SimTimeNs(f / kRate)));
      }
    }
    return s;
  }();
  return scene;
}

// CPU time of the process (s): the benchmark and the planner (one thread)
// run on this thread only, and time while descheduled on the shared machine
// is not the code's cost.
double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Per-call CPU and wall times (s) of one benchmark.
struct Timings {
  std::vector<double> cpu, wall;
  double cpu0 = 0;
  std::chrono::steady_clock::time_point wall0;
  void Start() {
    wall0 = std::chrono::steady_clock::now();
    cpu0 = CpuSeconds();
  }
  void Stop() {
    cpu.push_back(CpuSeconds() - cpu0);
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  }
};

void Report(benchmark::State& state, const Timings& t, int people) {
  const core::Summary c = core::Summarize(t.cpu), w = core::Summarize(t.wall);
  state.counters["cpu_p50_us"] = 1e6 * c.p50;
  state.counters["cpu_p90_us"] = 1e6 * c.p90;
  state.counters["cpu_max_us"] = 1e6 * c.max;
  state.counters["wall_p50_us"] = 1e6 * w.p50;
  state.counters["wall_p90_us"] = 1e6 * w.p90;
  state.counters["per_person_cpu_us"] = 1e6 * c.p50 / people;
}

void BM_Intent(benchmark::State& state) {
  const Scene& s = GetScene();
  const int n = static_cast<int>(state.range(0));
  intent_service::IntentEstimator estimator(s.model, s.cell.estimator);
  collision::JointMixture out;
  Timings timing;
  int64_t k = 0;
  for (auto _ : state) {
    timing.Start();
    for (int b = 0; b < n; ++b) {
      const auto& joints = s.frames[static_cast<std::size_t>(b)][static_cast<std::size_t>(k % kFrames)];
      const intent_service::SkeletonFrame frame{static_cast<uint32_t>(b + 1), static_cast<double>(k) / kRate, joints};
      if (!estimator.Update(frame, &out).accepted()) state.SkipWithError("frame rejected");
    }
    timing.Stop();
    ++k;
  }
  Report(state, timing, n);
}

void BM_RiskEvaluate(benchmark::State& state) {
  const Scene& s = GetScene();
  const int n = static_cast<int>(state.range(0));
  collision_risk::RiskMonitor monitor = *s.cell.monitor;
  const auto joints = s.cell.planner->robot().JointNames();
  const Eigen::VectorXd a = s.cell.tasks.back().goal, b = s.cell.tasks.front().goal;
  std::vector<double> times = {0.0, 2.0};
  std::vector<std::vector<double>> points = {{a.data(), a.data() + a.size()}, {b.data(), b.data() + b.size()}};
  Timings timing;
  int64_t f = 0;
  for (auto _ : state) {
    state.PauseTiming();  // this period's inputs: robot, trajectory, N skeletons and predictions
    const int64_t now = SimTimeNs(static_cast<double>(f) / kRate);
    monitor.UpdateRobotState(now, joints, points[0]);
    monitor.UpdateTrajectory(now, joints, times, points);
    for (int p = 0; p < n; ++p) {
      std::vector<std::string> names;
      std::vector<Eigen::Vector3d> pos;
      for (const auto& j : s.frames[static_cast<std::size_t>(p)][static_cast<std::size_t>(f % kFrames)]) {
        names.push_back(j.name);
        pos.push_back(j.position);
      }
      monitor.UpdateSkeleton(static_cast<cell::BodyId>(p + 1), now, names, pos);
      collision::JointMixture m = s.predictions[static_cast<std::size_t>(p)][static_cast<std::size_t>(f % kFrames)];
      m.t0_ns = now;
      if (auto why = monitor.UpdatePrediction(static_cast<cell::BodyId>(p + 1), m)) state.SkipWithError(why->c_str());
    }
    ++f;
    state.ResumeTiming();
    timing.Start();
    const collision_risk::RiskReport r = monitor.Evaluate(now);
    timing.Stop();
    if (r.num_predicted != n) state.SkipWithError("not every person's prediction was used");
  }
  Report(state, timing, n);
}

// The cell's tasks one after the other (each from the previous one's goal),
// 0.1 s of simulated time per cycle, the robot where its plan says.
void BM_ReplanCycle(benchmark::State& state) {
  const Scene& s = GetScene();
  const int n = static_cast<int>(state.range(0));
  trajopt::Replanner replanner(*s.cell.planner, *s.cell.body, s.cell.replanner);
  const auto joints = replanner.joint_names();
  Eigen::VectorXd q = s.cell.tasks.back().goal;
  std::size_t task = 0;
  uint32_t id = 0;
  std::optional<std::pair<int64_t, Eigen::MatrixXd>> plan;
  double dt = s.cell.planner->params().dt;
  Timings timing;
  int waits = 0, cycles = 0, tasks_done = 0;
  int64_t k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const int64_t now = SimTimeNs(1.0 + 0.1 * static_cast<double>(k));
    const int frame = static_cast<int>(std::lround((1.0 + 0.1 * static_cast<double>(k)) * kRate));
    if (plan) q = cell::JointTrajectory::Uniform(plan->first, dt, plan->second).PositionAt(now);
    replanner.UpdateRobotState(now, joints, {q.data(), q.data() + q.size()}, std::vector<double>(q.size(), 0.0));
    if (!replanner.busy()) {
      trajopt::TaskSpec t;
      t.id = ++id;
      t.name = s.cell.tasks[task].name;
      t.goal = planning::Goal::Joint(s.cell.tasks[task].goal);
      replanner.StartTask(t, now);
      task = (task + 1) % s.cell.tasks.size();
    }
    for (int p = 0; p < n; ++p) {
      collision::JointMixture m = s.predictions[static_cast<std::size_t>(p)][static_cast<std::size_t>(frame % kFrames)];
      m.t0_ns = SimTimeNs(frame / kRate);
      replanner.UpdatePrediction(static_cast<cell::BodyId>(p + 1), m);
    }
    ++k;
    state.ResumeTiming();
    timing.Start();
    const trajopt::CycleResult r = replanner.Cycle(now);
    timing.Stop();
    if (r.publish) plan = std::make_pair(r.start_ns, r.positions);
    dt = r.dt > 0 ? r.dt : dt;
    waits += r.waiting;
    cycles += r.planning_time > 0;
    tasks_done += r.outcome.has_value();
    if (r.planning_time > 0 && r.num_people != n) state.SkipWithError("not every person was planned against");
  }
  Report(state, timing, n);
  state.counters["waiting_cycles"] = waits;
  state.counters["planned_cycles"] = cycles;
  state.counters["tasks_ended"] = tasks_done;
}

BENCHMARK(BM_Intent)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RiskEvaluate)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ReplanCycle)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond)->Iterations(600);

}  // namespace
}  // namespace iplan::cell_sim

BENCHMARK_MAIN();
