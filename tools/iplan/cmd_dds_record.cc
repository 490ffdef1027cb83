// iplan record: writes the cell's topics (and the viewer's scene channel) to
// an MCAP file that Foxglove, the MCAP CLI and `iplan view --replay` read.
// There is no C++ MCAP library in Debian; the writer is Foxglove's own
// @mcap/core (npm), run by Node.js (web/tools/mcap_writer.mjs), which this
// command feeds one line per message through a pipe.
#include <signal.h>
#include <stdio.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "command_registry.h"
#include "dds_common.h"
#include "dds_viewer_common.h"
#include "iplan/core/atomic_file.h"
#include "iplan/framework/service.h"
#include "iplan/viewer/cell_bridge.h"
#include "iplan/viewer/web_dir.h"

namespace iplan::cli {
namespace {

using Clock = std::chrono::steady_clock;
volatile sig_atomic_t g_stop = 0;

struct RecordOptions {
  DdsOptions dds;
  std::string out, stats, config_dir;
  std::vector<std::string> topics;
  double duration = 0;
  bool no_scene = false;
};

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

int RunRecord(const RecordOptions& o) {
  const std::string web = viewer::WebDir(), node = viewer::NodeExecutable();
  if (web.empty() || node.empty()) {
    std::cerr << "iplan record: needs Node.js and the built web folder (run scripts/setup.sh)\n";
    return 2;
  }
  const std::filesystem::path dir = std::filesystem::absolute(o.out).parent_path();
  if (!std::filesystem::is_directory(dir)) {
    std::cerr << "iplan record: no folder " << dir << " for " << o.out << "\n";
    return 2;
  }
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<viewer::CellBridge> bridge;
  FILE* pipe = nullptr;
  try {
    std::optional<viewer::SceneBuilder> scene;
    if (!o.no_scene) {
      const std::string config = o.config_dir.empty() ? framework::DefaultConfigDir() : o.config_dir;
      scene.emplace(LoadViewerCellModel(config));
    }
    participant = MakeParticipant(o.dds, "iplan-record");
    viewer::CellBridgeOptions bo;
    bo.topics = o.topics;
    bo.schema_dir = web + "/dist/schemas";
    bridge = std::make_unique<viewer::CellBridge>(*participant, std::move(scene), bo,
                                                  [&](std::size_t c, uint64_t t, const std::string& j) {
                                                    fprintf(pipe, "m %zu %llu %s\n", c, static_cast<unsigned long long>(t),
                                                            j.c_str());
                                                  });
    const std::string cmd = Quote(node) + " " + Quote(web + "/tools/mcap_writer.mjs") + " " + Quote(o.out);
    pipe = popen(cmd.c_str(), "w");
    if (!pipe) throw std::runtime_error("cannot start " + cmd);
    for (std::size_t i = 0; i < bridge->channels().size(); ++i) {
      const auto& c = bridge->channels()[i];
      const nlohmann::json line = {{"id", i}, {"topic", c.topic}, {"schemaName", c.schema_name}, {"schema", c.schema}};
      fprintf(pipe, "c %s\n", line.dump().c_str());
    }
  } catch (const std::exception& e) {
    if (pipe) pclose(pipe);
    std::cerr << "iplan record: " << e.what() << "\n";
    return 2;
  }
  signal(SIGPIPE, SIG_IGN);
  g_stop = 0;
  signal(SIGINT, [](int) { g_stop = 1; });
  signal(SIGTERM, [](int) { g_stop = 1; });
  std::cout << "iplan record: recording " << bridge->channels().size() << " channels from domain "
            << participant->domain_id() << " to " << o.out << " (Ctrl-C stops)" << std::endl;
  const auto start = Clock::now();
  const auto end = o.duration > 0 ? start + std::chrono::milliseconds(static_cast<int64_t>(o.duration * 1e3))
                                  : Clock::time_point::max();
  while (!g_stop && Clock::now() < end) bridge->SpinOnce(std::chrono::milliseconds(50));
  const int status = pclose(pipe);
  const int rc = status == -1 ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  nlohmann::json stats = {{"file", o.out}, {"duration_s", seconds}, {"messages", nlohmann::json::object()}};
  std::cout << "iplan record: " << std::fixed << std::setprecision(1) << seconds << " s\n";
  for (std::size_t i = 0; i < bridge->channels().size(); ++i) {
    stats["messages"][bridge->channels()[i].topic] = bridge->counts()[i];
    std::cout << "  " << std::left << std::setw(34) << bridge->channels()[i].topic << bridge->counts()[i] << "\n";
  }
  if (rc != 0) {
    std::cerr << "iplan record: the MCAP writer failed (exit code " << rc << "); " << o.out << " is incomplete\n";
    return 1;
  }
  if (!o.stats.empty()) core::WriteFileAtomically(o.stats, stats.dump(2) + "\n");
  std::cout << "iplan record: wrote " << o.out << std::endl;
  return 0;
}

void Register(CLI::App& app) {
  static RecordOptions o;
  auto* r = app.add_subcommand("record",
                               "Record the cell's topics and the viewer's scene to an MCAP file (Foxglove, "
                               "iplan view --replay)");
  AddDdsOptions(r, &o.dds);
  r->add_option("--out", o.out, "MCAP file to write")->required();
  r->add_option("--topics", o.topics, "record only these topics (default: every iplan topic)");
  r->add_option("--duration", o.duration, "stop after this many seconds (0: until Ctrl-C or SIGTERM)");
  r->add_flag("--no-scene", o.no_scene, "do not record the viewer's scene channel");
  r->add_option("--stats", o.stats, "also write the messages recorded per topic as JSON to this file");
  r->add_option("--config-dir", o.config_dir, "cell configuration the scene is drawn from (default: as iplan view)");
  r->callback([] { SetExitCode(RunRecord(o)); });
}

const bool kRegistered = RegisterCommand("26-record", Register);

}  // namespace
}  // namespace iplan::cli
