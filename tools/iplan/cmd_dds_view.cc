// iplan view: the live 3D view of the cell in the browser, and the Foxglove
// WebSocket server a Foxglove app connects to (docs/viewer.md). With
// --replay it serves a recording (iplan record) to the page instead.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <thread>

#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "dds_common.h"
#include "dds_viewer_common.h"
#include "iplan/framework/service.h"
#include "iplan/viewer/cell_bridge.h"
#include "iplan/viewer/foxglove_server.h"
#include "iplan/viewer/web_dir.h"

namespace iplan::cli {
namespace {

using Clock = std::chrono::steady_clock;
volatile sig_atomic_t g_stop = 0;

struct ViewOptions {
  DdsOptions dds;
  int port = 8080;
  std::string bind = "127.0.0.1";
  std::string config_dir, robot, scene, body, replay;
  std::vector<std::string> topics;
  double duration = 0;
};

int RunView(const ViewOptions& o) {
  const std::string web = viewer::WebDir();
  if (web.empty()) {
    std::cerr << "iplan view: the page is not built (web/dist); run scripts/setup.sh or set $IPLAN_WEB_DIR\n";
    return 2;
  }
  viewer::FoxgloveServerOptions so;
  so.bind = o.bind;
  so.port = o.port;
  so.web_root = web + "/dist";
  if (!o.replay.empty()) {
    if (!std::filesystem::exists(o.replay)) {
      std::cerr << "iplan view: no recording " << o.replay << "\n";
      return 2;
    }
    so.files["/recording.mcap"] = o.replay;
  }
  std::unique_ptr<viewer::FoxgloveServer> server;
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<viewer::CellBridge> bridge;
  std::vector<uint32_t> ids;
  try {
    server = std::make_unique<viewer::FoxgloveServer>(so);
    if (o.replay.empty()) {
      const std::string config = o.config_dir.empty() ? framework::DefaultConfigDir() : o.config_dir;
      viewer::SceneBuilder scene(LoadViewerCellModel(config, o.robot, o.scene, o.body));
      participant = MakeParticipant(o.dds, "iplan-viewer");
      viewer::CellBridgeOptions bo;
      bo.topics = o.topics;
      bo.schema_dir = web + "/dist/schemas";
      bridge = std::make_unique<viewer::CellBridge>(
          *participant, std::move(scene), bo,
          [&](std::size_t c, uint64_t t, const std::string& j) { server->Publish(ids[c], t, j); },
          [&](std::size_t c) { return server->HasSubscribers(ids[c]); });
      for (const auto& c : bridge->channels()) {
        ids.push_back(server->AddChannel({c.topic, c.schema_name, c.schema, "json", c.topic != viewer::kCellTopic}));
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "iplan view: " << e.what() << "\n";
    return 2;
  }
  const std::string url = "http://" + (o.bind == "0.0.0.0" ? std::string("localhost") : o.bind) + ":" +
                          std::to_string(server->port()) + "/" + (o.replay.empty() ? "" : "?replay=recording.mcap");
  std::cout << "iplan view: open " << url << "\n  Foxglove: Open connection > Foxglove WebSocket > ws://"
            << (o.bind == "0.0.0.0" ? std::string("localhost") : o.bind) << ":" << server->port() << "\n"
            << (bridge ? "  bridging " + std::to_string(bridge->channels().size()) + " channels from DDS domain " +
                             std::to_string(participant->domain_id())
                       : "  replaying " + o.replay)
            << std::endl;
  g_stop = 0;
  signal(SIGINT, [](int) { g_stop = 1; });
  signal(SIGTERM, [](int) { g_stop = 1; });
  const auto end = o.duration > 0 ? Clock::now() + std::chrono::milliseconds(static_cast<int64_t>(o.duration * 1e3))
                                  : Clock::time_point::max();
  while (!g_stop && Clock::now() < end) {
    if (bridge) bridge->SpinOnce(std::chrono::milliseconds(50));
    else std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const auto st = server->stats();
  std::cout << "iplan view: " << st.messages_sent << " messages sent, " << st.messages_dropped
            << " dropped (slow clients), " << st.http_requests << " page requests";
  if (bridge) {
    const auto bs = bridge->stats();
    std::cout << "; scene inputs refused " << bs.scene_rejected
              << (bs.last_scene_rejection.empty() ? "" : " (last: " + bs.last_scene_rejection + ")");
  }
  std::cout << std::endl;
  return 0;
}

void Register(CLI::App& app) {
  static ViewOptions o;
  auto* v = app.add_subcommand("view",
                               "Serve the live 3D view of the cell (http://localhost:8080) and the Foxglove WebSocket "
                               "protocol on the same port; --replay serves a recording instead");
  AddDdsOptions(v, &o.dds);
  v->add_option("--port", o.port, "TCP port of the page and the WebSocket (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  v->add_option("--bind", o.bind, "address to listen on (0.0.0.0: every interface)")->capture_default_str();
  v->add_option("--config-dir", o.config_dir,
                "cell configuration; the robot, scene and body come from its trajopt.yaml (default: $IPLAN_CONFIG_DIR, "
                "installed, or source)");
  v->add_option("--robot", o.robot, "robot model instead: a DH YAML, a URDF or a URDF overlay (docs/robots.md)");
  v->add_option("--scene", o.scene, "scene file instead (config/scenes/*.yaml)");
  v->add_option("--body", o.body, "human body file instead (config/humans/*.yaml)");
  v->add_option("--topics", o.topics, "bridge only these topics (default: every iplan topic)");
  v->add_option("--replay", o.replay, "serve this recording (iplan record, MCAP) to the page, with a time slider");
  v->add_option("--duration", o.duration, "stop after this many seconds (0: until Ctrl-C)");
  v->callback([] { SetExitCode(RunView(o)); });
}

const bool kRegistered = RegisterCommand("25-view", Register);

}  // namespace
}  // namespace iplan::cli
