// iplan report: a self-contained HTML report (plots embedded, no network) of
// a demo run: its summary JSON (iplan demo --summary) and, when there is one,
// its recording (iplan demo --record / iplan record). The page is made by
// web/tools/report.mjs (Node.js), which reads the MCAP file with @mcap/core
// and inlines the uPlot plotting library.
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "command_registry.h"
#include "iplan/core/process.h"
#include "iplan/viewer/web_dir.h"

namespace iplan::cli {
namespace {

namespace fs = std::filesystem;

struct ReportOptions {
  std::string run, out, recording;
};

int RunReport(const ReportOptions& o) {
  const std::string web = viewer::WebDir(), node = viewer::NodeExecutable();
  if (web.empty() || node.empty()) {
    std::cerr << "iplan report: needs Node.js and the built web folder (run scripts/setup.sh)\n";
    return 2;
  }
  // RUN: the summary file, or a folder holding summary.json (and recording.mcap).
  fs::path summary = o.run;
  if (fs::is_directory(summary)) summary /= "summary.json";
  if (!fs::is_regular_file(summary)) {
    std::cerr << "iplan report: no summary " << summary << " (iplan demo --summary FILE writes one)\n";
    return 2;
  }
  std::string recording = o.recording;
  if (recording.empty()) {
    try {
      const auto j = nlohmann::json::parse(std::ifstream(summary));
      if (j.contains("recording") && j["recording"].is_string()) recording = j["recording"].get<std::string>();
    } catch (const std::exception& e) {
      std::cerr << "iplan report: " << summary.string() << " is not JSON: " << e.what() << "\n";
      return 2;
    }
  }
  if (recording.empty()) {
    const fs::path beside = summary.parent_path() / "recording.mcap";
    if (fs::exists(beside)) recording = beside.string();
  }
  const std::string out = o.out.empty() ? (summary.parent_path() / (summary.stem().string() + ".html")).string() : o.out;
  std::vector<std::string> argv = {node, web + "/tools/report.mjs", "--summary", summary.string(), "--out", out};
  if (!recording.empty()) argv.insert(argv.end(), {"--recording", recording});
  core::Process p(argv, {}, true);
  const auto rc = p.Wait(std::chrono::minutes(5));
  if (!rc || *rc != 0) {
    std::cerr << "iplan report: the report generator failed\n";
    return 1;
  }
  return 0;
}

void Register(CLI::App& app) {
  static ReportOptions o;
  auto* r = app.add_subcommand("report",
                               "Write a self-contained HTML report with plots of a demo run (summary JSON and recording)");
  r->add_option("run", o.run, "summary JSON of the run (iplan demo --summary), or a folder with summary.json")->required();
  r->add_option("--out", o.out, "HTML file to write (default: the summary's name with .html)");
  r->add_option("--recording", o.recording,
                "MCAP recording of the run (default: the summary's 'recording', or recording.mcap beside it)");
  r->callback([] { SetExitCode(RunReport(o)); });
}

const bool kRegistered = RegisterCommand("27-report", Register);

}  // namespace
}  // namespace iplan::cli
