// The whole cell, as users start it: `iplan demo` runs every service as a
// separate process on loopback DDS (the synthetic person, intent, collision
// risk, trajectory optimisation, the robot simulator and the supervisor) for
// one collaborative episode: with no flags (Cyclone DDS, secured with DDS
// Security, the user's keystore made on this first use), on Fast DDS
// (secured), and mixed (half the services on each vendor, --insecure: a
// secured --mixed is refused with its reason). Every robot task completes,
// the robot never touches the person's true body, and trajectories come
// with an end-to-end latency. The intent model is trained from the
// synthetic person on the first run (cached in config/models). The same
// with the UR5e of ../shared (--robot). Each demo
// gets an XDG_DATA_HOME of its own, so the user's keystore is the test's.
//
// However `iplan demo` ends (SIGINT, SIGKILL), it leaves no service of its
// cell running behind it.
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;

struct Variant {
  std::string name;
  std::vector<std::string> args;
};

class CellEpisode : public ::testing::TestWithParam<Variant> {};

TEST_P(CellEpisode, TasksCompleteWithoutContact) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("iplan-cell-episode-" + GetParam().name + "-" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string summary = (dir / "summary.json").string();
  std::vector<std::string> argv = {BinPath("iplan"),  "demo",        "--episodes", "1",
                                   "--timeout",       "100",         "--summary",  summary,
                                   "--state-dir",     dir.string(),  "--domain",   std::to_string(UniqueDomain(31)),
                                   "--config-dir",    std::string(IPLAN_SOURCE_DIR) + "/config"};
  argv.insert(argv.end(), GetParam().args.begin(), GetParam().args.end());
  Process demo(argv, {{"XDG_DATA_HOME", dir.string()}, {"IPLAN_SECURITY", ""}});
  const auto rc = demo.Wait(200s);
  ASSERT_TRUE(rc.has_value()) << "demo did not finish\n" << demo.Stdout();
  EXPECT_EQ(*rc, 0) << demo.Stdout() << demo.Stderr();
  std::ifstream in(summary);
  ASSERT_TRUE(in.good()) << "no summary\n" << demo.Stdout() << demo.Stderr();
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["failure"], "");
  EXPECT_EQ(j["episodes_completed"], 1);
  EXPECT_EQ(j["tasks_completed"], 5);  // every task of config/tasks/table_top.yaml
  EXPECT_EQ(j["true_contacts"], 0.0);
  EXPECT_GT(j["min_separation_m"].get<double>(), 0.0);
  EXPECT_LT(j["max_collision_bound"].get<double>(), 0.05);  // 1 - delta_cl of the risk service
  EXPECT_GT(j["latency_ms"]["count"].get<int>(), 20);
  EXPECT_GT(j["latency_ms"]["p50"].get<double>(), 0.0);
  EXPECT_LT(j["latency_ms"]["p99"].get<double>(), 1000.0);  // sanity only: the target lives in the demo figures
  for (const auto& [service, code] : j["service_exit_codes"].items()) EXPECT_EQ(code, 0) << service;
  // The stops, timed against the true person (the truth, the joint states
  // and the trajectories reached the demo's own participant).
  const nlohmann::json& audit = j["stop_audit"];
  ASSERT_TRUE(audit.is_object()) << demo.Stdout();
  EXPECT_GT(audit["judgements"].get<int>(), 50);
  EXPECT_GE(audit["each"].size(), 1u);  // the safe start at least
  EXPECT_LE(audit["each"].size(), j["protective_stops"].get<std::size_t>());
  for (const auto& stop : audit["each"]) {
    EXPECT_GE(stop["person_within_sp_s"].get<double>(), 0.0);
    EXPECT_NEAR(stop["outlast_s"].get<double>(),
                stop["duration_s"].get<double>() - stop["person_within_sp_s"].get<double>(), 1e-9);
  }
  EXPECT_GE(audit["unstopped_within_sp_s"]["total"].get<double>(), 0.0);
  EXPECT_NE(demo.Stdout().find("stops against the true person "), std::string::npos) << demo.Stdout();
  if (GetParam().name == "ur5e") {
    EXPECT_NE(demo.Stdout().find("robot ur5e ("), std::string::npos) << demo.Stdout();
    EXPECT_NE(demo.Stdout().find("6 joints), resting at ["), std::string::npos) << demo.Stdout();
  }
  if (GetParam().name == "mixed") {
    EXPECT_NE(j["vendors"]["intent"], j["vendors"]["perception"]);
    EXPECT_NE(j["vendors"]["trajopt"], j["vendors"]["supervisor"]);
    EXPECT_EQ(j["security"]["secured"], false);
    EXPECT_NE(demo.Stdout().find("no DDS Security (--insecure)"), std::string::npos) << demo.Stdout();
  } else {
    // Secured by default, with the keystore made on this first use.
    const std::string keystore = (dir / "iplan/keystore").string();
    EXPECT_EQ(j["security"]["secured"], true);
    EXPECT_EQ(j["security"]["keystore"], keystore);
    EXPECT_NE(demo.Stdout().find("keystore " + keystore + ", this user's, created now"), std::string::npos)
        << demo.Stdout();
    EXPECT_TRUE(std::filesystem::is_regular_file(keystore + "/enclaves/iplan-supervisor/key.pem"));
  }
  std::filesystem::remove_all(dir);
}

// A secured cell over both vendors cannot authenticate (Debian's Fast DDS 2.9
// and Cyclone DDS 0.10): `iplan demo --mixed` says so and starts nothing.
TEST(CellEpisodeMixed, SecuredIsRefusedWithItsReason) {
  const auto dir = std::filesystem::temp_directory_path() / ("iplan-mixed-refused-" + std::to_string(getpid()));
  Process demo({BinPath("iplan"), "demo", "--mixed", "--state-dir", dir.string(), "--config-dir",
                std::string(IPLAN_SOURCE_DIR) + "/config"},
               {{"XDG_DATA_HOME", dir.string()}, {"IPLAN_SECURITY", ""}});
  EXPECT_EQ(demo.Wait(30s), 2);
  EXPECT_NE(demo.Stderr().find("iplan demo: refused: --mixed runs secured only where both DDS vendors can "
                               "authenticate each other"),
            std::string::npos)
      << demo.Stderr();
  EXPECT_NE(demo.Stderr().find("Failed to convert octet sequence to ASN1 integer"), std::string::npos);
  EXPECT_NE(demo.Stderr().find("iplan demo --mixed --insecure"), std::string::npos);
  EXPECT_EQ(demo.Stdout().find("services:"), std::string::npos) << "services were started:\n" << demo.Stdout();
  std::filesystem::remove_all(dir);
}

// Pids of the running (not zombie) iplan services started with `--domain D`.
std::vector<int> ServicesOnDomain(int domain) {
  std::vector<int> pids;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string name = e.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream cmd(e.path() / "cmdline");
    std::vector<std::string> args;
    for (std::string a; std::getline(cmd, a, '\0');) args.push_back(a);
    if (args.empty() || args[0].find("/iplan-") == std::string::npos) continue;
    bool on_domain = false;
    for (size_t i = 0; i + 1 < args.size(); ++i) on_domain |= args[i] == "--domain" && args[i + 1] == std::to_string(domain);
    std::ifstream stat(e.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const auto close = line.rfind(')');
    const bool zombie = close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
    if (on_domain && !zombie) pids.push_back(std::stoi(name));
  }
  return pids;
}

class DemoEnds : public ::testing::TestWithParam<int> {};

// The demo is ended by a signal while its cell runs: within 2 s of the
// demo's end no service of that cell is left (SIGKILL: no clean-up code of
// the demo runs; the services get their parent-death signal).
TEST_P(DemoEnds, NoServiceOutlivesTheDemo) {
  const int sig = GetParam();
  const int domain = UniqueDomain(37 + sig);
  const auto dir = std::filesystem::temp_directory_path() / ("iplan-demo-ends-" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  Process demo({BinPath("iplan"), "demo", "--episodes", "20", "--timeout", "300", "--state-dir", dir.string(),
                "--domain", std::to_string(domain), "--config-dir", std::string(IPLAN_SOURCE_DIR) + "/config"},
               {{"XDG_DATA_HOME", dir.string()}, {"IPLAN_SECURITY", ""}});
  ASSERT_TRUE(demo.WaitForOutput("episodes: 20", 120s)) << demo.Stdout() << demo.Stderr();
  // Every service is up (each announces itself by its diagnostics soon after).
  std::this_thread::sleep_for(2s);
  const auto before = ServicesOnDomain(domain);
  ASSERT_EQ(before.size(), 6u) << "the cell's services, found by their --domain " << domain << "\n" << demo.Stdout();
  demo.Signal(sig);
  ASSERT_TRUE(demo.Wait(30s).has_value()) << "demo did not end on signal " << sig;
  const auto end = std::chrono::steady_clock::now() + 2s;
  while (!ServicesOnDomain(domain).empty() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(20ms);
  const auto left = ServicesOnDomain(domain);
  std::string which;  // the services left, and whether they end later
  for (const int pid : left) {
    std::ifstream cmd("/proc/" + std::to_string(pid) + "/cmdline");
    std::string exe;
    std::getline(cmd, exe, '\0');
    const auto give_up = std::chrono::steady_clock::now() + 10s;
    while (kill(pid, 0) == 0 && std::chrono::steady_clock::now() < give_up) std::this_thread::sleep_for(20ms);
    which += " " + exe + (kill(pid, 0) == 0 ? " (still there 10 s later)" : " (ended within 10 s more)");
    kill(pid, SIGKILL);
  }
  EXPECT_TRUE(left.empty()) << left.size() << " services still running 2 s after the demo ended by signal " << sig
                            << ":" << which;
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Signals, DemoEnds, ::testing::Values(SIGINT, SIGKILL),
                         [](const auto& info) { return info.param == SIGKILL ? "sigkill" : "sigint"; });

INSTANTIATE_TEST_SUITE_P(Vendors, CellEpisode,
                         ::testing::Values(Variant{"default", {}}, Variant{"fastdds", {"--dds", "fastdds"}},
                                           Variant{"mixed", {"--dds", "cyclonedds", "--mixed", "--insecure"}},
                                           // Another arm: the same cell file's task poses solved for it.
                                           Variant{"ur5e", {"--robot", std::string(IPLAN_SHARED_DIR) + "/robots/ur5e/ur5e.urdf"}}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace iplan::testing
