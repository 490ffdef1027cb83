// A real service process (iplan-perception) through the framework: bad
// configurations are refused with a message naming the key and the file;
// the service publishes diagnostics, stops cleanly on SIGTERM, and tells
// systemd it is ready and alive through NOTIFY_SOCKET.
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include <iterator>
#include <sstream>
#include <gtest/gtest.h>

#include "iplan/dds/participant.h"
#include "iplan/framework/node.h"
#include "test_node.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;

std::string WriteTemp(const std::string& name, const std::string& content) {
  const std::string path = "/tmp/iplan-svc-test-" + std::to_string(getpid()) + "-" + name;
  std::ofstream(path) << content;
  return path;
}

struct BadConfig {
  std::string yaml;
  std::string expected;
};

class RefusedConfig : public ::testing::TestWithParam<BadConfig> {};

TEST_P(RefusedConfig, ExitsWithCode2NamingKeyAndFile) {
  const std::string file = WriteTemp("bad.yaml", GetParam().yaml);
  Process p({BinPath("iplan-perception"), "--config", file, "--domain", std::to_string(UniqueDomain(5))});
  const auto rc = p.Wait(20s);
  ASSERT_TRUE(rc.has_value()) << "service did not refuse the configuration";
  EXPECT_EQ(*rc, 2);
  EXPECT_NE(p.Stderr().find(file + ": " + GetParam().expected), std::string::npos) << p.Stderr();
  std::remove(file.c_str());
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RefusedConfig,
    ::testing::Values(BadConfig{"perception:\n  rat_hz: 30\n", "unknown key 'perception.rat_hz'"},
                      BadConfig{"perception:\n  rate_hz: fast\n",
                                "key 'perception.rate_hz': expected a finite number, got 'fast'"},
                      BadConfig{"perception:\n  rate_hz: 0\n", "section 'perception': rate_hz must be in [0.5, 1000], got 0"},
                      BadConfig{"perception:\n  provider: kinect9\n",
                                "section 'perception': provider must be synthetic or replay, got 'kinect9'"},
                      BadConfig{"perception:\n  synthetic:\n    torso: [1, 2]\n",
                                "key 'perception.synthetic.torso': expected 3 numbers, got 2"},
                      BadConfig{"node:\n  diagnostics_period: -1\n", "section 'node': diagnostics_period must be >= 0, got -1"},
                      BadConfig{"perceptoin:\n  rate_hz: 30\n", "unknown key 'perceptoin'"},
                      BadConfig{"perception:\n  provider: replay\n",
                                "section 'perception': replay.file is required with provider replay"},
                      BadConfig{"perception:\n  provider: replay\n  replay:\n    file: " IPLAN_SHARED_DIR
                                "/data/florence3d.csv\n    joint_map:\n      wrist: hand_r\n",
                                "key 'perception.replay.joint_map.wrist': "},
                      BadConfig{"perception:\n  provider: replay\n  replay:\n    file: " IPLAN_SHARED_DIR
                                "/data/florence3d.csv\n    sequences: [florence_nope]\n",
                                "key 'perception.replay': sequence 'florence_nope' is not in"},
                      BadConfig{"perception:\n  replay:\n    transform:\n      matrix: [1, 0, 0]\n",
                                "section 'perception': replay.transform.matrix: must have 16 numbers"}));

// The fail-safe settings: a supervisor in deployment that watches nothing,
// a key written twice, an empty file, a robot obeying no monitor, a permit
// validity that one late permit would lapse.
struct SafetyConfig {
  std::string service;
  std::string yaml;
  std::string expected;
};
class RefusedSafetyConfig : public ::testing::TestWithParam<SafetyConfig> {};

TEST_P(RefusedSafetyConfig, ExitsWithCode2NamingTheProblem) {
  const std::string file = WriteTemp(GetParam().service + "-bad.yaml", GetParam().yaml);
  Process p({BinPath("iplan-" + GetParam().service), "--config", file, "--check-config", "--domain",
             std::to_string(UniqueDomain(6))});
  const auto rc = p.Wait(20s);
  ASSERT_TRUE(rc.has_value()) << "service did not refuse the configuration";
  EXPECT_EQ(*rc, 2) << p.Stdout() << p.Stderr();
  EXPECT_NE(p.Stderr().find(GetParam().expected), std::string::npos) << p.Stderr();
  std::remove(file.c_str());
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RefusedSafetyConfig,
    ::testing::Values(
        SafetyConfig{"supervisor", "supervisor:\n  mode: deployment\n  watch: []\n",
                     "section 'supervisor': watch must name at least one topic in deployment"},
        SafetyConfig{"supervisor", "supervisor:\n  permit_period: 0.1\n  permit_validity: 0.15\n",
                     "section 'supervisor': permit_validity must be at least twice permit_period"},
        SafetyConfig{"supervisor", "supervisor:\n  alpha: 0.1\n  alpha: 0.2\n", "key 'supervisor.alpha': appears twice"},
        SafetyConfig{"supervisor", "# nothing but a comment\n", "the file is empty"},
        SafetyConfig{"robot-sim", "robot_sim:\n  permits:\n    monitors: []\n",
                     "permits: no monitors configured"}));

TEST(ServiceFramework, MissingFileAndBadVendorAreRefused) {
  Process missing({BinPath("iplan-perception"), "--config", "/nonexistent/perception.yaml"});
  ASSERT_EQ(missing.Wait(20s), 2);
  EXPECT_NE(missing.Stderr().find("/nonexistent/perception.yaml: cannot open"), std::string::npos) << missing.Stderr();
  Process vendor({BinPath("iplan-perception"), "--dds", "opendds"});
  ASSERT_EQ(vendor.Wait(20s), 2);
  EXPECT_NE(vendor.Stderr().find("unknown DDS vendor 'opendds'"), std::string::npos) << vendor.Stderr();
  Process check({BinPath("iplan-perception"), "--check-config"});
  ASSERT_EQ(check.Wait(20s), 0) << check.Stderr();
  EXPECT_NE(check.Stdout().find("configuration is valid"), std::string::npos);
}

// --remap FROM:=TO and node.remap: accepted when well formed, refused with
// the reason and exit code 2 otherwise (a typo must not leave a topic
// silently unconnected).
TEST(ServiceFramework, RemappingsAreCheckedAtStart) {
  struct Case {
    std::vector<std::string> args;
    int code;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"--remap", "/joint_states:=/sim/joint_states"}, 0, "configuration is valid"},
      {{"-r", "joint_states:=sim/joint_states", "-r", "/iplan/robot/trajectory:=/arm_controller/joint_trajectory"},
       0, "configuration is valid"},
      {{"--set", "node.remap./joint_states=/sim/joint_states"}, 0, "configuration is valid"},
      {{"--remap", "/joint_state:=/x"}, 2, "remap: '/joint_state' is not a topic of the catalogue"},
      {{"--remap", "/joint_states"}, 2, "--remap: remap '/joint_states' is not FROM:=TO"},
      {{"--remap", "/joint_states:=/a//b"}, 2, "has an empty token ('//')"},
      {{"--set", "node.remap./joint_states=/iplan/task/command"}, 2, "two topics would be named /iplan/task/command"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> argv = {BinPath("iplan-robot-sim"), "--check-config"};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    Process p(argv);
    const std::string shown = c.args.front() + " " + c.args.at(1);
    ASSERT_EQ(p.Wait(20s), c.code) << shown << "\n" << p.Stderr();
    EXPECT_NE((p.Stdout() + p.Stderr()).find(c.says), std::string::npos) << shown << "\n" << p.Stdout() << p.Stderr();
  }
}

// node.realtime_priority and node.lock_memory either take effect (the
// process runs under SCHED_FIFO with its memory locked) or are refused with a
// message saying what to grant; the service runs either way.
TEST(ServiceFramework, RealtimeSchedulingTakesEffectOrIsReported) {
  Process svc({BinPath("iplan-perception"), "--domain", std::to_string(UniqueDomain(7)), "--set",
               "node.realtime_priority=10", "--set", "node.lock_memory=true"});
  std::this_thread::sleep_for(3s);
  ASSERT_TRUE(svc.Running()) << svc.Stderr();
  std::ifstream stat("/proc/" + std::to_string(svc.pid()) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  // Field 41 (policy) counted after the ')' closing the command name.
  std::istringstream fields(text.substr(text.rfind(')') + 2));
  std::vector<std::string> f{std::istream_iterator<std::string>(fields), std::istream_iterator<std::string>()};
  ASSERT_GE(f.size(), 39u);
  const int policy = std::stoi(f[38]);  // field 41 is the 39th after the state (field 3)
  std::ifstream status("/proc/" + std::to_string(svc.pid()) + "/status");
  std::string line, locked;
  while (std::getline(status, line)) {
    if (line.rfind("VmLck:", 0) == 0) locked = line;
  }
  const std::string err = svc.Stderr();
  if (err.find("SCHED_FIFO refused") == std::string::npos) {
    EXPECT_EQ(policy, 1) << "SCHED_FIFO neither set nor reported refused\n" << err;
  } else {
    EXPECT_NE(err.find("LimitRTPRIO=10"), std::string::npos) << err;
    EXPECT_EQ(policy, 0);
  }
  if (err.find("mlockall refused") == std::string::npos) {
    EXPECT_EQ(locked.find(" 0 kB"), std::string::npos) << "memory neither locked nor reported refused: " << locked;
  } else {
    EXPECT_NE(err.find("LimitMEMLOCK=infinity"), std::string::npos) << err;
  }
  svc.Signal(SIGTERM);
  EXPECT_EQ(svc.Wait(10s), 0) << err;
  Process bad({BinPath("iplan-perception"), "--check-config", "--set", "node.realtime_priority=120"});
  EXPECT_EQ(bad.Wait(20s), 2);
  EXPECT_NE(bad.Stderr().find("realtime_priority"), std::string::npos) << bad.Stderr();
}

TEST(ServiceFramework, PublishesDiagnosticsAndStopsCleanlyOnSigterm) {
  const int domain = UniqueDomain(6);
  Process svc({BinPath("iplan-perception"), "--domain", std::to_string(domain), "--dds", "fastdds"});
  TestNode observer("observer", dds::Vendor::kCyclone, domain);
  framework::Node& node = *observer.node;
  std::string state;
  int skeletons = 0;
  node.Subscribe(framework::topics::Diagnostics(),
                 std::function<void(const msg::DiagnosticArray&, const dds::SampleInfo&)>(
                     [&](const msg::DiagnosticArray& a, const dds::SampleInfo&) {
                       for (const auto& s : a.status) {
                         if (s.name == "perception") state = s.message;
                       }
                     }));
  node.Subscribe(framework::topics::HumanSkeleton(),
                 std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                     [&](const msg::HumanSkeleton& s, const dds::SampleInfo&) {
                       ++skeletons;
                       EXPECT_EQ(s.joints.size(), 9u);
                     }));
  const auto end = std::chrono::steady_clock::now() + 20s;
  while ((state != "active" || skeletons < 30) && std::chrono::steady_clock::now() < end) node.SpinOnce(50ms);
  EXPECT_EQ(state, "active");
  EXPECT_GE(skeletons, 30);
  svc.Signal(SIGTERM);
  const auto rc = svc.Wait(10s);
  ASSERT_TRUE(rc.has_value()) << "service did not stop on SIGTERM";
  EXPECT_EQ(*rc, 0) << svc.Stderr();
  EXPECT_NE(svc.Stderr().find("stopping"), std::string::npos);
}

TEST(ServiceFramework, NotifiesSystemdReadinessWatchdogAndStopping) {
  const std::string sock_path = "/tmp/iplan-notify-" + std::to_string(getpid()) + ".sock";
  ::unlink(sock_path.c_str());
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof(addr.sun_path), "%s", sock_path.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
  timeval tv{0, 100000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));

  Process svc({BinPath("iplan-perception"), "--domain", std::to_string(UniqueDomain(7))},
              {{"NOTIFY_SOCKET", sock_path}, {"WATCHDOG_USEC", "200000"}});
  std::vector<std::pair<double, std::string>> messages;
  const auto start = std::chrono::steady_clock::now();
  bool stopped = false;
  while (std::chrono::steady_clock::now() - start < 20s) {
    char buf[512];
    const ssize_t n = ::recv(fd, buf, sizeof(buf) - 1, 0);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (n > 0) messages.emplace_back(t, std::string(buf, static_cast<std::size_t>(n)));
    int watchdogs = 0;
    bool ready = false;
    for (const auto& [tm, m] : messages) {
      ready = ready || m.find("READY=1") != std::string::npos;
      if (m.find("WATCHDOG=1") != std::string::npos) ++watchdogs;
    }
    if (ready && watchdogs >= 5 && !stopped) {
      svc.Signal(SIGTERM);
      stopped = true;
    }
    if (stopped && !svc.Running()) break;
  }
  ::close(fd);
  ::unlink(sock_path.c_str());
  ASSERT_EQ(svc.Wait(5s), 0) << svc.Stderr();
  double ready_at = -1;
  std::vector<double> watchdog_at;
  bool stopping = false;
  for (const auto& [t, m] : messages) {
    if (m.find("READY=1") != std::string::npos) ready_at = t;
    if (m.find("WATCHDOG=1") != std::string::npos) watchdog_at.push_back(t);
    if (m.find("STOPPING=1") != std::string::npos) stopping = true;
  }
  ASSERT_GE(ready_at, 0) << "no READY=1";
  ASSERT_GE(watchdog_at.size(), 5u);
  EXPECT_TRUE(stopping) << "no STOPPING=1";
  // Keep-alives come at half the 200 ms interval: no gap may reach 200 ms.
  for (std::size_t i = 1; i < watchdog_at.size(); ++i) {
    EXPECT_LT(watchdog_at[i] - watchdog_at[i - 1], 0.2) << "watchdog gap at " << watchdog_at[i];
  }
}

}  // namespace
}  // namespace iplan::testing
