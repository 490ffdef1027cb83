// The cell on several computers: three "hosts" made by the test itself as
// Linux network namespaces on a bridge (tests/support/net_lab.h), the
// services spread as docs/deployment.md suggests (sensor host: perception
// and intent; planning host: trajectory optimisation, collision risk and
// the supervisor; robot host: the simulator), every process on the shipped
// network DDS profile (IPLAN_DDS_PROFILE=network, interface eth0), and the
// test's observer on a fourth host (an operator's computer on the same
// switch).
//
// - A full episode passes on Cyclone DDS, on Fast DDS, and mixed (sensor and
//   robot hosts on Fast DDS, the planning host on Cyclone): every task
//   succeeds, none fails, the robot never touches the person.
// - Network faults: the robot host's cable pulled while the arm moves -> the
//   robot, on its own, comes to rest within the permit validity plus its
//   stopping time (measured from its own /joint_states inside the robot
//   host) and the supervisor withdraws its permit within the joint-state
//   deadline; with the cable back the cell moves again. 20 % of the packets
//   every host receives dropped (nftables) -> the cell keeps working or stops
//   safely, and resumes once the loss is gone. Added delay runs only where
//   the kernel has netem (this test says which faults ran). The Q-table and
//   the intent model are intact afterwards.
//
// Needs root (CI runs as root); skipped with the reason elsewhere.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cell_harness.h"
#include "iplan/core/atomic_file.h"
#include "iplan/core/checksum.h"
#include "net_lab.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = CellHarness::Clock;

constexpr int kTasks = 5;  // every task of config/tasks/table_top.yaml

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Sets an environment variable for the scope (children inherit it).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// docs/deployment.md, "Several computers".
std::string HostOf(const std::string& svc) {
  if (svc == "perception" || svc == "intent") return "sensor";
  if (svc == "robot_sim") return "robot";
  return "planning";
}

struct Variant {
  std::string name;
  dds::Vendor planning;       // the planning host and the observer
  dds::Vendor sensor, robot;  // the other two hosts
};

void PrintTo(const Variant& v, std::ostream* os) { *os << v.name; }

// The lab, the network profile and the cell, torn down in reverse: the
// services, the observer's namespace, the variables, the namespaces.
class MultiHostCell {
 public:
  MultiHostCell(const std::string& tag, const Variant& v)
      : lab_({"sensor", "planning", "robot", "ops"}),
        profile_("IPLAN_DDS_PROFILE", "network"),
        interface_("IPLAN_DDS_INTERFACE", "eth0"),
        ops_(lab_.Namespace("ops")),
        cell_(tag, v.planning, 91),
        variant_(v) {
    for (const auto& svc : CellHarness::Services()) {
      const std::string host = HostOf(svc);
      cell_.Place(svc, lab_.On(host), host == "sensor" ? v.sensor : host == "robot" ? v.robot : v.planning);
    }
  }
  NetLab& lab() { return lab_; }
  CellHarness& cell() { return cell_; }
  const Variant& variant() const { return variant_; }

 private:
  NetLab lab_;
  ScopedEnv profile_, interface_;
  InNamespace ops_;
  CellHarness cell_;
  Variant variant_;
};

// Distinct tasks that succeeded in outcomes[from...], and how many failed.
std::pair<int, int> TaskCounts(const CellHarness& cell, std::size_t from) {
  std::set<std::string> ok;
  int failed = 0;
  const auto& o = cell.outcomes();
  for (std::size_t i = from; i < o.size(); ++i) {
    if (o[i].status == msg::TaskOutcome::SUCCEEDED) {
      ok.insert(o[i].task_name);
    } else {
      ++failed;
    }
  }
  return {static_cast<int>(ok.size()), failed};
}

std::string Why(CellHarness& cell) {
  return "supervisor: " + cell.LastReason("supervisor") + "; collision risk: " + cell.LastReason("collision_risk");
}

#define IPLAN_SKIP_WITHOUT_NAMESPACES()                              \
  if (const std::string why = NetLab::Unavailable(); !why.empty()) { \
    GTEST_SKIP() << "multi-host test skipped: " << why;              \
  }

class MultiHost : public ::testing::TestWithParam<Variant> {};

TEST_P(MultiHost, EpisodeSpreadOverThreeHosts) {
  IPLAN_SKIP_WITHOUT_NAMESPACES();
  MultiHostCell mh("multi-host-" + GetParam().name, GetParam());
  CellHarness& cell = mh.cell();
  ASSERT_TRUE(cell.ready());
  const auto t0 = Clock::now();
  cell.StartAll();
  ASSERT_TRUE(cell.SpinUntil([&] { return TaskCounts(cell, 0).first >= kTasks; }, 150s))
      << "episode incomplete after " << Seconds(Clock::now() - t0) << " s: " << TaskCounts(cell, 0).first
      << " tasks succeeded; " << Why(cell) << "\n"
      << cell.Logs("supervisor") << cell.Logs("robot_sim");
  std::cout << GetParam().name << ": " << kTasks << " tasks over three hosts in " << Seconds(Clock::now() - t0)
            << " s from the start of the services\n";
  EXPECT_EQ(TaskCounts(cell, 0).second, 0) << "tasks failed or were cancelled";
  EXPECT_GT(cell.MaxSpeedSince(t0), 0.2);  // the trajectories reached the robot host
  cell.ExpectNoContactAndCleanShutdown();
}

INSTANTIATE_TEST_SUITE_P(
    Vendors, MultiHost,
    ::testing::Values(Variant{"cyclonedds", dds::Vendor::kCyclone, dds::Vendor::kCyclone, dds::Vendor::kCyclone},
                      Variant{"fastdds", dds::Vendor::kFastDds, dds::Vendor::kFastDds, dds::Vendor::kFastDds},
                      Variant{"mixed", dds::Vendor::kCyclone, dds::Vendor::kFastDds, dds::Vendor::kFastDds}),
    [](const auto& info) { return info.param.name; });

// The robot's own joint states, recorded inside the robot host by
// `iplan topic echo` (the observer cannot hear it while its cable is out).
struct RobotSample {
  int64_t stamp_ns = 0;  // header.stamp, the robot's clock (the same machine's)
  double max_speed = 0;  // rad/s
};
std::vector<RobotSample> RobotSamples(const Process& echo) {
  std::vector<RobotSample> out;
  std::istringstream in(echo.Stdout());
  for (std::string line; std::getline(in, line);) {
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.contains("header")) continue;
    RobotSample s;
    s.stamp_ns =
        j["header"]["stamp"]["sec"].get<int64_t>() * 1000000000 + j["header"]["stamp"]["nanosec"].get<int64_t>();
    for (const auto& v : j["velocity"]) s.max_speed = std::max(s.max_speed, std::abs(v.get<double>()));
    out.push_back(s);
  }
  return out;
}
int64_t WallNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

constexpr double kPermitValidity = 0.2;  // s, a permit's validity at the robot (docs/safety.md)
constexpr double kStoppingTime = 0.3;    // s, robot_sim.stopping_time
constexpr double kJointDeadline = 0.1;   // s, /joint_states deadline at the supervisor
constexpr double kSlack = 0.25;          // s, scheduling on a loaded 2-core machine, 20 ms joint-state period
constexpr auto kCut = 12s;               // long against every deadline and liveliness lease; within the 20 s participant lease

// Cable out while the arm moves; returns the robot's rest latency, s.
double CutTheRobotHost(MultiHostCell& mh, const Process& echo) {
  CellHarness& cell = mh.cell();
  const int64_t cut_ns = WallNs();
  const auto cut = Clock::now();
  mh.lab().SetLink("robot", false);
  EXPECT_TRUE(cell.SpinUntil([&] { return !cell.Permits("supervisor"); }, 3s)) << Why(cell);
  const double withdrawn = Seconds(Clock::now() - cut);
  cell.SpinFor(std::chrono::duration_cast<std::chrono::milliseconds>(kCut - (Clock::now() - cut)));
  const auto samples = RobotSamples(echo);
  std::optional<int64_t> rest;  // from here to the newest sample at rest
  int after_cut = 0;
  for (const auto& s : samples) {
    if (s.stamp_ns < cut_ns) continue;
    ++after_cut;
    if (s.max_speed < 1e-3) {
      if (!rest) rest = s.stamp_ns;
    } else {
      rest.reset();
    }
  }
  EXPECT_GT(after_cut, 50) << "the robot host published too little while cut off";
  EXPECT_TRUE(rest.has_value()) << "the robot still moved when its cable was plugged back";
  const double rest_s = rest ? (*rest - cut_ns) * 1e-9 : 1e9;
  std::cout << "robot host cut off: supervisor permit withdrawn after " << withdrawn << " s ("
            << cell.LastReason("supervisor") << "); robot at rest " << rest_s
            << " s after the cut (its own /joint_states)\n";
  EXPECT_LE(withdrawn, kJointDeadline + kSlack);
  EXPECT_LE(rest_s, kPermitValidity + kStoppingTime + kSlack);
  mh.lab().SetLink("robot", true);
  return rest_s;
}

// A supervisor stop caused by the network (an input late, gone or stale),
// as opposed to one the cell itself decides (separation, collision risk).
bool NetworkStop(const std::string& reason) {
  for (const char* cause : {"deadline missed", "never seen", "liveliness", "no usable sample", "stale"}) {
    if (reason.find(cause) != std::string::npos) return true;
  }
  return false;
}

// Runs the cell under a fault for kFaultRun. It keeps working or stops
// safely: no contact, no service lost; once the fault is gone, no stop is
// the network's any more (the cell moves, or it holds for a reason of its
// own, e.g. the person inside the protective separation).
constexpr auto kFaultRun = 20s;
void UnderFault(MultiHostCell& mh, const std::string& what, const std::function<void(bool)>& fault) {
  CellHarness& cell = mh.cell();
  const std::size_t from = cell.outcomes().size();
  const auto start = Clock::now();
  int stops = 0;
  bool permitted = true;
  Clock::duration held{};
  auto last = start;
  fault(true);
  cell.SpinUntil(
      [&] {
        const bool p = cell.Permits("supervisor") && cell.Permits("collision_risk");
        if (permitted && !p) ++stops;
        if (p) held += Clock::now() - last;
        last = Clock::now();
        permitted = p;
        return false;
      },
      kFaultRun);
  const auto [ok, failed] = TaskCounts(cell, from);
  std::cout << what << ": " << ok << " tasks succeeded, " << failed << " failed or cancelled, " << stops
            << " protective stops, both permits held " << 100 * Seconds(held) / Seconds(Clock::now() - start)
            << " % of " << Seconds(Clock::now() - start) << " s; true contacts "
            << cell.DiagNumber("robot_sim", "true_contacts", -1) << "\n";
  fault(false);
  const auto off = Clock::now();
  EXPECT_EQ(cell.DiagNumber("robot_sim", "true_contacts", -1), 0) << what;
  for (const auto& svc : CellHarness::Services()) EXPECT_TRUE(cell[svc].Running()) << what << ": " << svc << " died";
  // Recovered: moving, or 5 s in a row without a network stop.
  auto clean_since = Clock::now();
  const bool recovered = cell.SpinUntil(
      [&] {
        if (NetworkStop(cell.LastReason("supervisor"))) clean_since = Clock::now();
        return cell.MaxSpeedSince(off) > 0.2 || Clock::now() - clean_since > 5s;
      },
      30s);
  if (!recovered) {
    // Whose side is stuck: a fresh reader on the planning host.
    std::vector<std::string> hz = mh.lab().On("planning");
    hz.insert(hz.end(), {BinPath("iplan"), "topic", "hz", "/iplan/human/prediction", "--duration", "3", "--dds",
                         dds::ToString(mh.variant().planning), "--domain", std::to_string(cell.domain())});
    std::string out;
    NetLab::Run(hz, &out);
    ADD_FAILURE() << "still a network stop after " << what << " ended; " << Why(cell)
                  << "\na new reader of /iplan/human/prediction on the planning host:\n"
                  << out;
  }
  std::cout << what << " removed: after " << Seconds(Clock::now() - off) << " s "
            << (cell.MaxSpeedSince(off) > 0.2 ? "moving again" : "at rest, held by the cell: " + Why(cell)) << "\n";
}

// Packet loss (nftables) at 5 % and 20 %, then added delay where the kernel
// has netem; says which of them ran.
void LossAndDelay(MultiHostCell& mh) {
  std::string ran = "cable out";
  if (const std::string why = mh.lab().LossUnavailable(); why.empty()) {
    for (const int percent : {5, 20}) {
      UnderFault(mh, std::to_string(percent) + " % packet loss on every host", [&](bool on) {
        for (const char* h : {"sensor", "planning", "robot"}) mh.lab().SetLoss(h, on ? percent : 0);
      });
      ran += ", " + std::to_string(percent) + " % loss";
    }
  } else {
    std::cout << "packet-loss fault NOT run: " << why << "\n";
  }
  if (const std::string why = mh.lab().DelayUnavailable(); why.empty()) {
    UnderFault(mh, "20 ms added delay on every host", [&](bool on) {
      for (const char* h : {"sensor", "planning", "robot"}) mh.lab().SetDelay(h, on ? 20 : 0);
    });
    ran += ", 20 ms delay";
  } else {
    std::cout << "delay fault NOT run: this kernel has no netem (tc: " << why << ")\n";
  }
  std::cout << "network faults run: " << ran << "\n";
  ::testing::Test::RecordProperty("faults_run", ran);
}

struct FaultVariant {
  Variant hosts;
  bool loss_and_delay;  // also the packet-loss and delay phases (one variant: the suite's time)
};
void PrintTo(const FaultVariant& v, std::ostream* os) {
  *os << v.hosts.name << (v.loss_and_delay ? ", cable out, loss and delay" : ", cable out");
}
class MultiHostFaults : public ::testing::TestWithParam<FaultVariant> {};

TEST_P(MultiHostFaults, CableOutLossAndDelay) {
  IPLAN_SKIP_WITHOUT_NAMESPACES();
  const Variant& v = GetParam().hosts;
  MultiHostCell mh("multi-host-faults-" + v.name, v);
  CellHarness& cell = mh.cell();
  ASSERT_TRUE(cell.ready());
  const std::uint64_t model_hash = core::Fnv1a64(core::ReadFile(cell.model()), core::kIplanFnvSeed);
  std::vector<std::string> echo_argv = mh.lab().On("robot");
  echo_argv.insert(echo_argv.end(), {BinPath("iplan"), "topic", "echo", "/joint_states", "--dds",
                                     dds::ToString(v.robot), "--domain", std::to_string(cell.domain())});
  Process echo(echo_argv);
  cell.StartAll();
  // A learned table to keep: some task has ended.
  ASSERT_TRUE(cell.SpinUntil([&] { return std::filesystem::exists(cell.q_table()); }, 120s)) << "no task ended";
  // Moving with both permits: whatever stops the arm now is the fault.
  ASSERT_TRUE(cell.SpinUntil(
      [&] { return cell.Moving() && cell.Permits("supervisor") && cell.Permits("collision_risk"); }, 120s))
      << Why(cell) << "\n"
      << cell.Logs("robot_sim");
  CutTheRobotHost(mh, echo);
  const auto replugged = Clock::now();
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.MaxSpeedSince(replugged) > 0.2; }, 60s))
      << "no motion after the cable is back; " << Why(cell);
  std::cout << "robot host back: moving again " << Seconds(Clock::now() - replugged) << " s after the replug\n";

  if (GetParam().loss_and_delay) LossAndDelay(mh);
  cell.ExpectNoContactAndCleanShutdown();
  // Nothing lost: the model unchanged, the Q-table loads with what it learned.
  EXPECT_EQ(core::Fnv1a64(core::ReadFile(cell.model()), core::kIplanFnvSeed), model_hash) << cell.model();
  cell.Start("supervisor");
  EXPECT_TRUE(cell.SpinUntil(
      [&] { return cell["supervisor"].Stderr().find("loaded " + cell.q_table()) != std::string::npos; }, 10s))
      << cell["supervisor"].Stderr();
  cell["supervisor"].Signal(SIGTERM);
  EXPECT_EQ(cell["supervisor"].Wait(10s), 0);
}

INSTANTIATE_TEST_SUITE_P(
    Vendors, MultiHostFaults,
    ::testing::Values(
        FaultVariant{{"cyclonedds", dds::Vendor::kCyclone, dds::Vendor::kCyclone, dds::Vendor::kCyclone}, true},
        FaultVariant{{"mixed", dds::Vendor::kCyclone, dds::Vendor::kCyclone, dds::Vendor::kFastDds}, false}),
    [](const auto& info) { return info.param.hosts.name; });

// The loss phases on Fast DDS too; not in the suite (its time), run with
// build/tests/multi_host_test --gtest_also_run_disabled_tests --gtest_filter='DISABLED_*'
INSTANTIATE_TEST_SUITE_P(
    DISABLED_FastDds, MultiHostFaults,
    ::testing::Values(
        FaultVariant{{"fastdds", dds::Vendor::kFastDds, dds::Vendor::kFastDds, dds::Vendor::kFastDds}, true}),
    [](const auto& info) { return info.param.hosts.name; });

}  // namespace
}  // namespace iplan::testing
