#include "dds_viewer_common.h"

#include <signal.h>

#include <chrono>
#include <stdexcept>

#include "iplan/framework/service_file.h"
#include "services/trajopt/trajopt_config.h"

namespace iplan::cli {

viewer::CellModel LoadViewerCellModel(const std::string& config_dir, const std::string& robot, const std::string& scene,
                                      const std::string& body) {
  // The robot, scene and person the trajectory optimiser plans with.
  const trajopt::TrajoptConfig t = trajopt::LoadTrajoptConfig(framework::CellFile(config_dir, "trajopt"), robot);
  return viewer::LoadCellModel(t.robot_file, scene.empty() ? t.scene_file : scene, body.empty() ? t.human_body_file : body);
}

std::unique_ptr<core::Process> StartRecorder(const std::string& vendor, int domain, const std::string& out,
                                             const std::string& config_dir, const std::string& log_base,
                                             const std::map<std::string, std::string>& env) {
  auto p = std::make_unique<core::Process>(
      std::vector<std::string>{core::ExecutableDir() + "/iplan", "record", "--dds", vendor, "--domain",
                               std::to_string(domain), "--out", out, "--stats", out + ".stats.json", "--config-dir",
                               config_dir},
      env, false, log_base);
  if (!p->WaitForOutput("recording", std::chrono::seconds(20))) {
    throw std::runtime_error("iplan record did not start:\n" + p->Stdout() + p->Stderr());
  }
  return p;
}

std::optional<std::string> StopRecorder(core::Process& recorder) {
  recorder.Signal(SIGTERM);
  const auto rc = recorder.Wait(std::chrono::seconds(60));
  if (!rc) return "iplan record did not finish within 60 s";
  if (*rc != 0) return "iplan record exited with " + std::to_string(*rc) + ":\n" + recorder.Stderr();
  return std::nullopt;
}

std::optional<std::string> WriteReport(const std::string& summary, const std::string& recording, const std::string& out) {
  std::vector<std::string> argv = {core::ExecutableDir() + "/iplan", "report", summary, "--out", out};
  if (!recording.empty()) argv.insert(argv.end(), {"--recording", recording});
  core::Process p(argv);
  const auto rc = p.Wait(std::chrono::seconds(120));
  if (!rc || *rc != 0) return "iplan report failed:\n" + p.Stdout() + p.Stderr();
  return std::nullopt;
}

}  // namespace iplan::cli
