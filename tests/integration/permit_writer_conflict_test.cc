// Stop wins (issue 27 part 3), the whole cell as separate processes, without
// DDS Security, on Cyclone DDS and on Fast DDS: with the cell in protective
// stop (perception frozen, so the supervisor and collision risk send STOPs),
// two participants that *name* themselves iplan-supervisor and
// iplan-collision_risk (what USER_DATA says; anyone can) publish PERMITs at
// 50 Hz for 3 s (the Fast DDS variant is disabled: see the end of the
// file). Measured on the code before this test: the arm moved at
// 0.59 rad/s. Now the real monitors' STOPs are held against them, the robot
// stays at rest, its diagnostics name both writers of each monitor and its
// log reports each conflict once; after the forgers go quiet the cell
// resumes by itself.
#include <signal.h>

#include <iostream>
#include <regex>

#include <gtest/gtest.h>

#include "cell_harness.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = CellHarness::Clock;

struct Variant {
  std::string name;
  dds::Vendor vendor;
};

class PermitWriterConflict : public ::testing::TestWithParam<Variant> {};

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

// A forged PERMIT: fresh stamp, validity 5 s (the robot caps it at 0.25 s).
void WritePermit(dds::Writer<msg::SafetyPermit>& w, const std::string& source) {
  msg::SafetyPermit p;
  p.header.stamp = msg::Now();
  p.state = msg::SafetyPermit::PERMIT;
  p.validity = 5;
  p.source = source;
  p.reason = "all inputs healthy";
  w.Write(p);
}

TEST_P(PermitWriterConflict, ForgedMonitorNamesDoNotLiftAStopAndAreReportedNamingBothWriters) {
  const Variant& v = GetParam();
  // The forgers: participants of their own, named like the real monitors.
  // Declared before the cell so they go after it: deleting a Fast DDS 2.9
  // writer while the cell's readers still talk to it hung the test process
  // (in DataWriterImpl's destructor) here.
  std::unique_ptr<TestNode> fake_sup, fake_risk;
  CellHarness cell("permit-conflict-" + v.name, v.vendor, 83);
  ASSERT_TRUE(cell.ready());
  fake_sup = std::make_unique<TestNode>("iplan-supervisor", v.vendor, cell.domain());
  fake_risk = std::make_unique<TestNode>("iplan-collision_risk", v.vendor, cell.domain());
  auto& sup_w = fake_sup->node->Advertise(framework::topics::SafetyPermit());
  auto& risk_w = fake_risk->node->Advertise(framework::topics::SafetyPermit());
  const auto started = Clock::now();
  cell.StartAll();
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.Moving(); }, 90s))
      << "the cell does not work; supervisor: " << cell.LastReason("supervisor") << "\n" << cell.Logs("robot_sim");
  std::cout << "cell moving after " << std::chrono::duration<double>(Clock::now() - started).count() << " s\n";
  ASSERT_TRUE(cell.SpinUntil([&] { return !cell.Diag("robot_sim", "permit_writer_conflicts").empty(); }, 5s));
  EXPECT_EQ(cell.DiagNumber("robot_sim", "permit_writer_conflicts", -1), 0) << cell.Diag("robot_sim", "permit");

  // Protective stop: perception frozen.
  cell[std::string("perception")].Signal(SIGSTOP);
  cell.SpinFor(1s);
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.AtRest() && cell.RestSince(Clock::now() - 1s); }, 5s));
  ASSERT_FALSE(cell.Permits("supervisor"));

  // The forgers' writers must have matched the cell's permit readers
  // (robot-sim, trajopt, the observer), or the test would prove nothing.
  ASSERT_TRUE(cell.SpinUntil([&] { return sup_w.MatchedReaders() >= 3 && risk_w.MatchedReaders() >= 3; }, 10s))
      << "forged writers matched " << sup_w.MatchedReaders() << " and " << risk_w.MatchedReaders() << " readers";
  // The forgery: PERMITs claiming both monitors, 50 Hz, 3 s, fresh stamps.
  const auto attack = Clock::now();
  bool reason_named_both = false;
  std::string seen_reason;
  const std::regex both_sup("2 writers claim iplan-supervisor \\(writer ([0-9a-f]{16}), writer ([0-9a-f]{16})\\)");
  int sent = 0;
  while (Clock::now() - attack < 3s) {
    const auto t = Clock::now();
    WritePermit(sup_w, "supervisor");
    WritePermit(risk_w, "collision_risk");
    ++sent;
    const std::string reason = cell.Diag("robot_sim", "permit");
    std::smatch mt;
    if (std::regex_search(reason, mt, both_sup) && mt[1] != mt[2]) {
      reason_named_both = true;
      seen_reason = reason;
    }
    cell.SpinFor(std::chrono::milliseconds(20) - std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t));
  }
  cell.SpinFor(1200ms);  // a diagnostics period
  const double speed = cell.MaxSpeedSince(attack);
  std::cout << "forged permits sent: " << sent << " per monitor; arm speed during and after: " << speed
            << " rad/s\nrobot permit reason during the attack: " << seen_reason
            << "\npermit_writer_conflict: " << cell.Diag("robot_sim", "permit_writer_conflict") << "\n";
  EXPECT_GE(sent, 120);
  EXPECT_LT(speed, 0.01) << "forged monitor names moved the stopped robot";
  EXPECT_TRUE(reason_named_both) << "last permit diagnostic: " << cell.Diag("robot_sim", "permit");
  // Both monitors were claimed twice: two conflicts, each logged once.
  EXPECT_EQ(cell.DiagNumber("robot_sim", "permit_writer_conflicts"), 2);
  std::smatch mt;
  const std::string conflict = cell.Diag("robot_sim", "permit_writer_conflict");
  EXPECT_TRUE(std::regex_search(conflict, mt, std::regex("2 writers claim iplan-(supervisor|collision_risk) "
                                                         "\\(writer ([0-9a-f]{16}), writer ([0-9a-f]{16})\\)")) &&
              mt[2] != mt[3])
      << conflict;
  const std::string log = cell.Logs("robot_sim");
  EXPECT_EQ(Count(log, "PERMIT WRITER CONFLICT: 2 writers claim iplan-supervisor"), 1u) << log;
  EXPECT_EQ(Count(log, "PERMIT WRITER CONFLICT: 2 writers claim iplan-collision_risk"), 1u) << log;

  // The forgers quiet, perception back: the fault clears after
  // writer_silence (2 s) and the cell moves again.
  cell[std::string("perception")].Signal(SIGCONT);
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.Moving(); }, 30s)) << cell.Diag("robot_sim", "permit");
  EXPECT_EQ(Count(cell.Logs("robot_sim"), "permit writer conflict cleared"), 2u);
  cell.ExpectNoContactAndCleanShutdown();
}

INSTANTIATE_TEST_SUITE_P(Vendors, PermitWriterConflict,
                         ::testing::Values(Variant{"cyclonedds", dds::Vendor::kCyclone}),
                         [](const auto& info) { return info.param.name; });
// Fast DDS: passes when it finishes (0 rad/s, both writers named), but in
// about 1 of 10 runs the test process hangs in Fast DDS 2.9 (a stack trace
// showed DataWriterImpl's destructor while a forger was torn down; once in
// a clean-clone suite run it hit ctest's 300 s limit). Root cause not found;
// kept out of the suite until it is. Run it with
// --gtest_also_run_disabled_tests --gtest_filter='*fastdds*'.
INSTANTIATE_TEST_SUITE_P(DISABLED_Vendors, PermitWriterConflict,
                         ::testing::Values(Variant{"fastdds", dds::Vendor::kFastDds}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace iplan::testing
