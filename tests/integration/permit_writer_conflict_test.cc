// Forged service names against the whole cell (six services, separate
// processes), on Cyclone DDS and on Fast DDS, with the cell in protective
// stop (perception frozen, so both monitors send STOPs). The attackers are
// processes of their own (cell_forger), each participant *naming* itself
// like a service (what USER_DATA says; anyone can) and publishing, for 3 s:
// PERMITs for the monitor it names (50 Hz, validity 5 s), "OK" verdicts,
// a trajectory away from where the arm stands (10 Hz), a CANCEL of the
// running task and that task's outcome SUCCEEDED.
//
// Secured, the default configuration (as `iplan demo` and the units run
// the cell): attackers without credentials, and attackers holding the
// cell's observer identity (its certificate and key) under permissions of
// their own CA, claim iplan-supervisor, iplan-collision_risk and
// iplan-trajopt: none of their writers ever matches a reader of the cell,
// the arm stays at rest, the task is neither cancelled nor counted done,
// and no service even has a stranger to ignore. The supervisor's own
// enclave, stolen and run a second time, may publish the supervisor's
// permits but not collision risk's (refused), and its PERMITs do not lift
// the real supervisor's STOP: the robot reports two writers claiming
// iplan-supervisor, naming both.
//
// With --insecure: participants merely named iplan-supervisor and
// iplan-collision_risk (the attack that moved the arm at 0.59 rad/s before
// issue 27) leave it at rest: the real monitors' STOPs are held against
// them, the robot's diagnostics name both writers of each monitor and its
// log reports each conflict once.
//
// Either way the cell resumes by itself once the attack is over and
// perception is back.
#include <signal.h>

#include <iostream>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

#include "cell_harness.h"
#include "test_keystores.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = CellHarness::Clock;

const auto* const kKeystores = ::testing::AddGlobalTestEnvironment(new TestKeystores);

struct Variant {
  std::string name;
  dds::Vendor vendor;
  bool secured;
};

class ForgedNames : public ::testing::TestWithParam<Variant> {};

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

// One attacker process: `names` claimed, with `keystore`/`enclave` or none.
std::unique_ptr<Process> StartForger(const CellHarness& cell, const std::vector<std::string>& names,
                                     const std::string& keystore, const std::string& enclave, uint32_t task,
                                     const std::vector<double>& joints) {
  std::vector<std::string> argv = {TestBinPath("cell_forger"), "--dds", dds::ToString(cell.vendor()), "--domain",
                                   std::to_string(cell.domain()), "--rate", "50", "--for", "3"};
  for (const auto& n : names) argv.insert(argv.end(), {"--as", n});
  if (!keystore.empty()) argv.insert(argv.end(), {"--security", keystore, "--enclave", enclave});
  if (task != 0) argv.insert(argv.end(), {"--task", std::to_string(task)});
  std::string q;
  for (double x : joints) q += (q.empty() ? "" : ",") + std::to_string(x);
  if (joints.size() == 7) argv.insert(argv.end(), {"--joints", q});
  return std::make_unique<Process>(argv);
}

// Waits until the forger reports at least `n` readers matched on `topic`
// (its "matched <topic> <m>" lines; Fast DDS may count a reader more than once).
bool WaitMatched(Process& forger, const std::string& topic, int n, std::chrono::seconds timeout) {
  const std::regex line("matched " + topic + " (\\d+)");
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    const std::string out = forger.Stdout();
    int last = -1;
    for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator(); ++it) {
      last = std::stoi((*it)[1]);
    }
    if (last >= n) return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

// "sent <topic> <n> matched <m>" of a finished forger: topic -> {n, m}.
std::map<std::string, std::pair<int, int>> Sent(const std::string& out) {
  std::map<std::string, std::pair<int, int>> r;
  const std::regex line("sent (\\S+) (\\d+) matched (\\d+)");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator(); ++it) {
    r[(*it)[1]] = {std::stoi((*it)[2]), std::stoi((*it)[3])};
  }
  return r;
}

// What the robot's permit diagnostic said while the attack ran.
struct Watched {
  double max_speed = 0;
  std::string conflict_reason;  // a "2 writers claim iplan-supervisor (...)" reason, two distinct writers
};

class Attack {
 public:
  explicit Attack(const Variant& v)
      : v_(v), cell("forged-" + v.name, v.vendor, 83, v.secured ? TestKeystores::Cell() : "") {}

  void StartCellAndStop() {
    ASSERT_TRUE(cell.ready());
    using SI = const dds::SampleInfo&;
    cell.node().Subscribe(framework::topics::TaskCommand(),
                          std::function<void(const msg::TaskCommand&, SI)>([this](const msg::TaskCommand& c, SI) {
                            if (c.command == msg::TaskCommand::START) running_ = c.task_id;
                          }),
                          framework::SubscribeOptions{false});
    const auto started = Clock::now();
    cell.StartAll();
    ASSERT_TRUE(cell.SpinUntil([&] { return cell.Moving() && running_ != 0; }, 90s))
        << "the cell does not work; supervisor: " << cell.LastReason("supervisor") << "\n" << cell.Logs("robot_sim");
    std::cout << v_.name << ": cell moving after " << std::chrono::duration<double>(Clock::now() - started).count()
              << " s\n";
    ASSERT_TRUE(cell.SpinUntil([&] { return !cell.Diag("robot_sim", "permit_writer_conflicts").empty(); }, 5s));
    EXPECT_EQ(cell.DiagNumber("robot_sim", "permit_writer_conflicts", -1), 0) << cell.Diag("robot_sim", "permit");
    // Protective stop: perception frozen.
    cell[std::string("perception")].Signal(SIGSTOP);
    cell.SpinFor(1s);
    ASSERT_TRUE(cell.SpinUntil([&] { return cell.AtRest() && cell.RestSince(Clock::now() - 1s); }, 5s));
    ASSERT_FALSE(cell.Permits("supervisor"));
    completed_before_ = cell.DiagNumber("supervisor", "tasks_completed");
  }

  // Starts the attackers and waits until they are ready (and, where they
  // can, matched the cell's readers: else the test would prove nothing).
  void StartForgers() {
    const std::vector<std::string> monitors = {"iplan-supervisor", "iplan-collision_risk"};
    if (!v_.secured) {
      forgers_.push_back(StartForger(cell, monitors, "", "", 0, {}));
      ASSERT_TRUE(WaitMatched(*forgers_[0], "rt/iplan/safety/permit/supervisor", 3, 20s))
          << forgers_[0]->Stdout() << forgers_[0]->Stderr();
      ASSERT_TRUE(WaitMatched(*forgers_[0], "rt/iplan/safety/permit/collision_risk", 2, 10s)) << forgers_[0]->Stdout();
      return;
    }
    const std::vector<std::string> all = {"iplan-supervisor", "iplan-collision_risk", "iplan-trajopt"};
    const std::string observer = framework::kObserverEnclave;
    forgers_.push_back(StartForger(cell, all, "", "", running_, cell.positions()));
    forgers_.push_back(StartForger(cell, all, TestKeystores::StolenObserver(), observer, running_, cell.positions()));
    forgers_.push_back(StartForger(cell, monitors, TestKeystores::Cell(), "iplan-supervisor", 0, {}));
    for (auto& f : forgers_) ASSERT_TRUE(f->WaitForOutput("ready", 30s)) << f->Stdout() << f->Stderr();
    // The stolen supervisor matched the robot, trajopt and the observer; the
    // others had as long to try.
    ASSERT_TRUE(WaitMatched(*forgers_[2], "rt/iplan/safety/permit/supervisor", 3, 20s))
        << forgers_[2]->Stdout() << forgers_[2]->Stderr();
    cell.SpinFor(1s);
  }

  Watched Run() {
    const std::regex both("2 writers claim iplan-supervisor \\(writer ([0-9a-f]{16}), writer ([0-9a-f]{16})\\)");
    Watched w;
    const auto attack = Clock::now();
    for (auto& f : forgers_) f->Signal(SIGUSR1);
    while (Clock::now() - attack < 3s) {
      cell.SpinFor(20ms);
      const std::string reason = cell.Diag("robot_sim", "permit");
      std::smatch m;
      if (std::regex_search(reason, m, both) && m[1] != m[2]) w.conflict_reason = reason;
    }
    cell.SpinFor(1200ms);  // a diagnostics period
    for (auto& f : forgers_) EXPECT_EQ(f->Wait(10s), 0) << f->Stdout() << f->Stderr();
    w.max_speed = cell.MaxSpeedSince(attack);
    return w;
  }

  void Resume() {
    cell[std::string("perception")].Signal(SIGCONT);
    ASSERT_TRUE(cell.SpinUntil([&] { return cell.Moving(); }, 30s)) << cell.Diag("robot_sim", "permit");
  }

  const Variant& v_;
  CellHarness cell;
  std::vector<std::unique_ptr<Process>> forgers_;
  uint32_t running_ = 0;
  double completed_before_ = 0;
};

TEST_P(ForgedNames, DoNotMoveAStoppedRobotOrCommandTheCell) {
  const Variant& v = GetParam();
  Attack a(v);
  ASSERT_NO_FATAL_FAILURE(a.StartCellAndStop());
  ASSERT_NO_FATAL_FAILURE(a.StartForgers());
  const Watched w = a.Run();
  std::cout << v.name << ": arm speed during and after the attack " << w.max_speed
            << " rad/s\nrobot permit reason during the attack: " << w.conflict_reason
            << "\npermit_writer_conflict: " << a.cell.Diag("robot_sim", "permit_writer_conflict") << "\n";
  for (auto& f : a.forgers_) std::cout << "forger:\n" << f->Stdout();
  EXPECT_LT(w.max_speed, 0.01) << "forged names moved the stopped robot";
  EXPECT_FALSE(w.conflict_reason.empty()) << "last permit diagnostic: " << a.cell.Diag("robot_sim", "permit");
  const std::string log = a.cell.Logs("robot_sim");
  EXPECT_EQ(Count(log, "PERMIT WRITER CONFLICT: 2 writers claim iplan-supervisor"), 1u) << log;
  if (v.secured) {
    // Nothing of the strangers' reached the cell: sent, never matched.
    for (std::size_t i = 0; i < 2; ++i) {
      const auto sent = Sent(a.forgers_[i]->Stdout());
      EXPECT_EQ(sent.size(), 6u) << a.forgers_[i]->Stdout();
      for (const auto& [topic, nm] : sent) {
        EXPECT_GE(nm.first, topic.find("permit") != std::string::npos ? 120 : 20) << topic;
        EXPECT_EQ(nm.second, 0) << "forger " << i << "'s writer on " << topic << " matched the cell";
      }
    }
    EXPECT_NE(a.forgers_[2]->Stdout().find("refused rt/iplan/safety/permit/collision_risk"), std::string::npos)
        << "the supervisor's enclave may publish collision risk's permits:\n" << a.forgers_[2]->Stdout();
    for (const char* svc : {"robot_sim", "trajopt", "supervisor"}) {
      EXPECT_EQ(a.cell.DiagNumber(svc, "ignored_writers", -1), 0) << svc;
    }
    EXPECT_EQ(a.cell.DiagNumber("robot_sim", "permit_writer_conflicts"), 1);
    EXPECT_EQ(a.cell.DiagNumber("supervisor", "tasks_completed"), a.completed_before_)
        << "the supervisor counted a forged outcome";
  } else {
    // Both monitors were claimed twice: two conflicts, each logged once.
    EXPECT_EQ(a.cell.DiagNumber("robot_sim", "permit_writer_conflicts"), 2);
    EXPECT_EQ(Count(log, "PERMIT WRITER CONFLICT: 2 writers claim iplan-collision_risk"), 1u) << log;
  }
  std::smatch mt;
  const std::string conflict = a.cell.Diag("robot_sim", "permit_writer_conflict");
  EXPECT_TRUE(std::regex_search(conflict, mt, std::regex("2 writers claim iplan-(supervisor|collision_risk) "
                                                         "\\(writer ([0-9a-f]{16}), writer ([0-9a-f]{16})\\)")) &&
              mt[2] != mt[3])
      << conflict;

  // The attack over, perception back: the fault clears after writer_silence
  // (2 s) and the cell moves again; the task the forgers tried to cancel
  // was never cancelled.
  ASSERT_NO_FATAL_FAILURE(a.Resume());
  EXPECT_EQ(Count(a.cell.Logs("robot_sim"), "permit writer conflict cleared"), v.secured ? 1u : 2u);
  for (const auto& o : a.cell.outcomes()) {
    EXPECT_NE(o.status, msg::TaskOutcome::CANCELLED) << "task " << o.task_id << " cancelled: " << o.reason;
  }
  a.cell.ExpectNoContactAndCleanShutdown();
}

INSTANTIATE_TEST_SUITE_P(Vendors, ForgedNames,
                         ::testing::Values(Variant{"cyclonedds", dds::Vendor::kCyclone, true},
                                           Variant{"fastdds", dds::Vendor::kFastDds, true},
                                           Variant{"cyclonedds_insecure", dds::Vendor::kCyclone, false},
                                           Variant{"fastdds_insecure", dds::Vendor::kFastDds, false}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace iplan::testing
