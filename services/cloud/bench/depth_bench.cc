// The depth-camera path per 640x480 frame, on the demo cell (config/): the
// simulated camera rendering the scene (config/scenes/cell.yaml), the
// synthetic person's true body spheres (config/perception.yaml, its script
// over 10 s) and the robot's collision spheres, with noise; and the cloud
// service's whole stage on those frames (workspace crop, self-filter from
// the joint state, table, segmentation, tracking, voxel-reduced human
// points with covariances), beside the obstacle pipeline alone and the
// textbook PCL pipeline on the same frames. Pinned to one core; counters
// in milliseconds:
//   cpu_p50_ms, cpu_p99_ms, cpu_max_ms  thread CPU time per frame
//   wall_p50_ms, wall_p99_ms            wall-clock time per frame
//
//   build/bench/depth_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <sched.h>

#include <chrono>
#include <ctime>
#include <functional>

#include "services/cloud/core/cloud_stage.h"
#include "services/perception/core/depth_camera.h"
#include "iplan/collision/human_model.h"
#include "iplan/collision/scene.h"
#include "iplan/core/process.h"
#include "iplan/core/stats.h"
#include "services/cloud/core/cloud_settings.h"
#include "iplan/framework/service_file.h"
#include "services/perception/perception_settings.h"

namespace {

using namespace iplan;
constexpr int kFrames = 300;  // 10 s at 30 Hz

std::string Cfg(const std::string& f) { return std::string(IPLAN_SOURCE_DIR) + "/config/" + f; }

struct Cell {
  perception::DepthCameraParams camera;
  cloud_service::CloudStageParams stage;
  collision::RobotModel robot = collision::LoadRobotModelFromYaml(Cfg("robots/panda.yaml"));
  Eigen::VectorXd q = (Eigen::VectorXd(7) << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785).finished();
  std::vector<perception::DepthScene> scenes;  // one per frame
};

const Cell& TheCell() {
  static const Cell cell = [] {
    Cell c;
    // The cell's files, read as their services read them.
    cloud_service::CloudSettings cloud_settings;
    framework::ServiceFile(Cfg("cloud.yaml")).ReadSection("cloud", &cloud_settings).Finish();
    c.stage.X_WS = c.camera.X_WS = cloud_settings.camera.Pose();
    c.stage.pipeline = cloud::LoadCloudParams(Cfg("cloud_pipeline.yaml"));
    perception::PerceptionSettings perception_settings;
    framework::ServiceFile(Cfg("perception.yaml")).ReadSection("perception", &perception_settings).Finish();
    perception::SyntheticPerson person(perception_settings.synthetic.Person());
    person.StartScript(0);
    const collision::HumanBodyModel body(collision::LoadHumanBodyParams(Cfg("humans/upper_body.yaml")));
    perception::DepthScene fixed;
    for (const auto& o : collision::LoadSceneParams(Cfg("scenes/cell.yaml")).objects) {
      if (o.shape == collision::SceneObject::Shape::kBox) fixed.boxes.push_back({o.X_WO, o.size});
      else fixed.cylinders.push_back({o.X_WO, o.radius, o.length});
    }
    collision::RobotData data(c.robot);
    collision::CalcForwardKinematics(c.robot, c.q, &data);
    for (std::size_t k = 0; k < c.robot.spheres.size(); ++k)
      fixed.spheres.push_back({data.p_WS.col(static_cast<Eigen::Index>(k)), c.robot.spheres[k].radius});
    const std::vector<double> radii = body.Radii();
    for (int f = 0; f < kFrames; ++f) {
      perception::DepthScene s = fixed;
      const auto joints = person.TruePose(f / 30.0);
      Eigen::Matrix3Xd J(3, body.num_joints());
      for (int j = 0; j < body.num_joints(); ++j)
        for (const auto& js : joints)
          if (js.name == body.params().joints[static_cast<std::size_t>(j)]) J.col(j) = js.position_W;
      for (int k = 0; k < body.num_spheres(); ++k) s.spheres.push_back({body.SphereCentre(k, J), radii[static_cast<std::size_t>(k)]});
      c.scenes.push_back(std::move(s));
    }
    return c;
  }();
  return cell;
}

using iplan::core::ThreadCpuSeconds;

void Run(benchmark::State& state, const std::function<void(int frame)>& step) {
  std::vector<double> cpu, wall;
  int k = 0;
  for (auto _ : state) {
    const double c0 = ThreadCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    step(k++ % kFrames);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cpu.push_back(ThreadCpuSeconds() - c0);
    wall.push_back(s);
    state.SetIterationTime(s);
  }
  const auto c = core::Summarize(cpu);
  const auto w = core::Summarize(wall);
  state.counters["cpu_p50_ms"] = 1e3 * c.p50;
  state.counters["cpu_p99_ms"] = 1e3 * c.p99;
  state.counters["cpu_max_ms"] = 1e3 * c.max;
  state.counters["wall_p50_ms"] = 1e3 * w.p50;
  state.counters["wall_p99_ms"] = 1e3 * w.p99;
}

void BM_SimulatedCamera(benchmark::State& state) {
  const Cell& cell = TheCell();
  perception::DepthCameraParams p = cell.camera;
  p.add_noise = state.range(0) != 0;
  perception::SimulatedDepthCamera cam(p);
  cloud::Cloud c;
  Run(state, [&](int f) { cam.Render(cell.scenes[static_cast<std::size_t>(f)], &c); });
}

// The camera's frames of the cell, with noise, rendered once.
const std::vector<cloud::Cloud>& Frames() {
  static const std::vector<cloud::Cloud> frames = [] {
    const Cell& cell = TheCell();
    perception::SimulatedDepthCamera cam(cell.camera);
    std::vector<cloud::Cloud> out(kFrames);
    for (int f = 0; f < kFrames; ++f) cam.Render(cell.scenes[static_cast<std::size_t>(f)], &out[static_cast<std::size_t>(f)]);
    return out;
  }();
  return frames;
}

void BM_CloudStage(benchmark::State& state) {
  const Cell& cell = TheCell();
  const std::vector<cloud::Cloud>& frames = Frames();
  cloud_service::CloudStage stage(cell.stage, &cell.robot);
  cloud::Cloud work;
  std::size_t human = 0, n = 0;
  Run(state, [&](int f) {
    work = frames[static_cast<std::size_t>(f)];  // the copy the service decodes into (not timed apart)
    human += static_cast<std::size_t>(stage.Process(&work, cell.q, f * 33'333'333LL).human.size());
    ++n;
  });
  state.counters["human_points"] = static_cast<double>(human) / static_cast<double>(std::max<std::size_t>(1, n));
}

// The obstacle pipeline alone on the same frames (no crop, self-filter,
// tracking or human points): what the rest of the stage adds.
void BM_PipelineOnly(benchmark::State& state) {
  const std::vector<cloud::Cloud>& frames = Frames();
  cloud::ObstaclePipeline pipeline(TheCell().stage.pipeline);
  Run(state, [&](int f) { benchmark::DoNotOptimize(pipeline.Process(frames[static_cast<std::size_t>(f)])); });
}

// The textbook PCL pipeline (crop box, voxel grid, RANSAC plane, Euclidean
// clusters: cloud::TextbookPipeline) with the stage's pipeline parameters
// on the same frames, already cropped to the stage's workspace (untimed,
// so that the room's walls, which the stage's first step removes, do not
// inflate the textbook's time); no self-filter: issue 29's yardstick for
// the whole stage ("at most half the textbook pipeline's time").
void BM_Textbook(benchmark::State& state) {
  const Cell& cell = TheCell();
  const cloud_service::CloudStage stage(cell.stage, nullptr);
  std::vector<cloud::Cloud> frames = Frames();
  cloud_service::StageOutput cropped;
  for (cloud::Cloud& c : frames) stage.Crop(&c, &cropped);
  Run(state, [&](int f) {
    benchmark::DoNotOptimize(cloud::TextbookPipeline(frames[static_cast<std::size_t>(f)], cell.stage.pipeline));
  });
}

BENCHMARK(BM_SimulatedCamera)->Arg(1)->Arg(0)->Iterations(kFrames)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CloudStage)->Iterations(kFrames)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipelineOnly)->Iterations(kFrames)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Textbook)->Iterations(kFrames)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  iplan::core::PinToCurrentCpu();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
