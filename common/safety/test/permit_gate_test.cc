#include "iplan/safety/permit_gate.h"

#include <cmath>

#include <gtest/gtest.h>

namespace iplan::safety {
namespace {

constexpr int64_t kMs = 1000000;
constexpr int64_t kT0 = 1700000000000 * kMs;  // an arbitrary wall-clock time
constexpr uint64_t kSup = 0x1111, kRisk = 0x2222, kRogue = 0xbad;  // writer identities

PermitGate TwoMonitors() {
  PermitGateParams p;
  p.monitors = {"iplan-supervisor", "iplan-collision_risk"};
  p.max_validity = 0.25;
  p.clock_tolerance = 0.05;
  return PermitGate(p);
}

TEST(PermitGate, StopsUntilEveryMonitorPermits) {
  PermitGate g = TwoMonitors();
  EXPECT_FALSE(g.Evaluate(kT0).permitted);
  EXPECT_NE(g.Evaluate(kT0).reason.find("no permit from iplan-supervisor yet"), std::string::npos);
  ASSERT_FALSE(g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0));
  EXPECT_FALSE(g.Evaluate(kT0).permitted);
  EXPECT_NE(g.Evaluate(kT0).reason.find("iplan-collision_risk"), std::string::npos);
  ASSERT_FALSE(g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0, kT0));
  EXPECT_TRUE(g.Evaluate(kT0 + 100 * kMs).permitted);
}

TEST(PermitGate, OneStopIsEnough) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", kRisk, false, 0.2, "separation below S_p", kT0, kT0);
  const PermitDecision d = g.Evaluate(kT0 + kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("iplan-collision_risk stops: separation below S_p"), std::string::npos) << d.reason;
}

// Speed reduction rides on the permits: the robot runs at 1 minus the
// largest reduction of the permits it holds; a reduction outside [0, 1] is
// refused and changes nothing.
TEST(PermitGate, TheLargestSpeedReductionOfThePermitsHeldApplies) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0, kT0);
  EXPECT_EQ(g.Evaluate(kT0 + kMs).speed_scale, 1.0);
  ASSERT_FALSE(g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "speed reduced", kT0 + 10 * kMs, kT0 + 10 * kMs, 0.6));
  PermitDecision d = g.Evaluate(kT0 + 11 * kMs);
  EXPECT_TRUE(d.permitted);
  EXPECT_NEAR(d.speed_scale, 0.4, 1e-12);
  EXPECT_TRUE(g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "bad", kT0 + 20 * kMs, kT0 + 20 * kMs, 1.5));
  EXPECT_TRUE(g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "bad", kT0 + 20 * kMs, kT0 + 20 * kMs, std::nan("")));
  EXPECT_NEAR(g.Evaluate(kT0 + 21 * kMs).speed_scale, 0.4, 1e-12);
  ASSERT_FALSE(g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0 + 30 * kMs, kT0 + 30 * kMs, 0.0));
  EXPECT_EQ(g.Evaluate(kT0 + 31 * kMs).speed_scale, 1.0);
}

TEST(PermitGate, APermitLapsesAfterItsValidity) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0, kT0);
  EXPECT_TRUE(g.Evaluate(kT0 + 199 * kMs).permitted);
  const PermitDecision d = g.Evaluate(kT0 + 200 * kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("lapsed"), std::string::npos) << d.reason;
}

TEST(PermitGate, AMonitorCannotGrantMoreThanTheRobotAllows) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", kSup, true, 5.0, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", kRisk, true, 5.0, "clear", kT0, kT0);
  EXPECT_TRUE(g.Evaluate(kT0 + 249 * kMs).permitted);
  EXPECT_FALSE(g.Evaluate(kT0 + 250 * kMs).permitted);  // max_validity 0.25 s
}

TEST(PermitGate, ADelayedPermitLapsesEarly) {
  PermitGate g = TwoMonitors();
  // Stamped 150 ms before it arrives (replayed or held up): it is good only
  // until stamp + tolerance + validity = kT0 + 50 ms + 200 ms.
  g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0 + 150 * kMs);
  g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0 + 150 * kMs, kT0 + 150 * kMs);
  EXPECT_TRUE(g.Evaluate(kT0 + 249 * kMs).permitted);
  EXPECT_FALSE(g.Evaluate(kT0 + 250 * kMs).permitted);
}

TEST(PermitGate, AForgedClockBuysNoTime) {
  PermitGate g = TwoMonitors();
  const auto why = g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0 + 3600000 * kMs, kT0);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("ahead of this clock"), std::string::npos) << *why;
  EXPECT_FALSE(g.Evaluate(kT0).permitted);
  // And a refused future permit does not block the real ones after it.
  EXPECT_FALSE(g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0 + 10 * kMs, kT0 + 10 * kMs));
  EXPECT_FALSE(g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0 + 10 * kMs, kT0 + 10 * kMs));
  EXPECT_TRUE(g.Evaluate(kT0 + 20 * kMs).permitted);
}

TEST(PermitGate, AnOlderPermitIsRefused) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", kSup, false, 0.2, "deadline missed", kT0 + 100 * kMs, kT0 + 100 * kMs);
  g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0 + 100 * kMs, kT0 + 100 * kMs);
  // A replay of an earlier PERMIT must not lift the newer STOP.
  const auto why = g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0 + 110 * kMs);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("older than the permit held"), std::string::npos);
  EXPECT_FALSE(g.Evaluate(kT0 + 120 * kMs).permitted);
}

TEST(PermitGate, StrangersAreRefused) {
  PermitGate g = TwoMonitors();
  const auto why = g.OnPermit("rogue", kRogue, true, 0.2, "trust me", kT0, kT0);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("not a configured monitor"), std::string::npos);
  EXPECT_FALSE(g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", kT0, kT0));
  EXPECT_FALSE(g.Evaluate(kT0).permitted);
}

TEST(PermitGate, ParamsAreChecked) {
  EXPECT_THROW(PermitGate(PermitGateParams{}), std::invalid_argument);
  PermitGateParams p;
  p.monitors = {"a", "a"};
  EXPECT_THROW(PermitGate{p}, std::invalid_argument);
  p.monitors = {"a"};
  p.max_validity = 0;
  EXPECT_THROW(PermitGate{p}, std::invalid_argument);
  p.max_validity = 0.25;
  p.writer_silence = 0;
  EXPECT_THROW(PermitGate{p}, std::invalid_argument);
  p.writer_silence = 2.0;
  EXPECT_NO_THROW(PermitGate{p});
}

// Both monitors permitting from their own writers, from `t` every 50 ms
// until `end` (exclusive).
void BothPermit(PermitGate* g, int64_t t, int64_t end) {
  for (; t < end; t += 50 * kMs) {
    g->OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", t, t);
    g->OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", t, t);
  }
}

TEST(PermitGate, AStopIsHeldAgainstAnotherWritersPermits) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-collision_risk", kRisk, true, 5.0, "clear", kT0, kT0);
  ASSERT_FALSE(g.OnPermit("iplan-supervisor", kSup, false, 0.2, "perception: deadline missed", kT0, kT0));
  // A second writer claiming the supervisor permits, newer stamps, 50 Hz.
  for (int64_t t = kT0 + 10 * kMs; t < kT0 + 190 * kMs; t += 20 * kMs) {
    EXPECT_FALSE(g.OnPermit("iplan-supervisor", kRogue, true, 5.0, "all inputs healthy", t, t));
    const PermitDecision d = g.Evaluate(t);
    EXPECT_FALSE(d.permitted) << "at " << (t - kT0) / kMs << " ms";
    EXPECT_NE(d.reason.find("iplan-supervisor stops: perception: deadline missed"), std::string::npos) << d.reason;
  }
}

TEST(PermitGate, TwoWritersClaimingOneMonitorAreAFaultNamingBoth) {
  PermitGate g = TwoMonitors();
  BothPermit(&g, kT0, kT0 + 500 * kMs);
  EXPECT_TRUE(g.Evaluate(kT0 + 460 * kMs).permitted);
  EXPECT_TRUE(g.TakeConflictEvents(kT0 + 460 * kMs).empty());
  // A second writer claims the supervisor and says the same as the real one.
  ASSERT_FALSE(g.OnPermit("iplan-supervisor", kRogue, true, 0.2, "healthy", kT0 + 470 * kMs, kT0 + 470 * kMs));
  const PermitDecision d = g.Evaluate(kT0 + 480 * kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("2 writers claim iplan-supervisor (writer 0000000000001111, writer 0000000000000bad)"),
            std::string::npos)
      << d.reason;
  EXPECT_NE(d.reason.find("silent for 2.000 s"), std::string::npos) << d.reason;
  // Reported once, however many samples follow.
  const auto events = g.TakeConflictEvents(kT0 + 480 * kMs);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_TRUE(events[0].raised);
  EXPECT_EQ(events[0].monitor, "iplan-supervisor");
  EXPECT_EQ(events[0].first_writer, kSup);
  EXPECT_EQ(events[0].second_writer, kRogue);
  EXPECT_EQ(events[0].description, d.reason);
  for (int64_t t = kT0 + 500 * kMs; t < kT0 + 1500 * kMs; t += 20 * kMs) {
    g.OnPermit("iplan-supervisor", kRogue, true, 0.2, "healthy", t, t);
    if ((t - kT0) % (50 * kMs) == 0) {
      g.OnPermit("iplan-supervisor", kSup, true, 0.2, "healthy", t, t);
      g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", t, t);
    }
    EXPECT_FALSE(g.Evaluate(t).permitted) << "at " << (t - kT0) / kMs << " ms";
    EXPECT_TRUE(g.TakeConflictEvents(t).empty()) << "reported again at " << (t - kT0) / kMs << " ms";
  }
  // The second writer's last sample was at 1480 ms: the fault holds for
  // writer_silence (2 s) after it, then clears (once) and the real writer's
  // permits count again.
  BothPermit(&g, kT0 + 1500 * kMs, kT0 + 3470 * kMs);
  EXPECT_FALSE(g.Evaluate(kT0 + 3470 * kMs).permitted);
  EXPECT_TRUE(g.TakeConflictEvents(kT0 + 3470 * kMs).empty());
  EXPECT_TRUE(g.Evaluate(kT0 + 3480 * kMs).permitted) << g.Evaluate(kT0 + 3480 * kMs).reason;
  const auto cleared = g.TakeConflictEvents(kT0 + 3480 * kMs);
  ASSERT_EQ(cleared.size(), 1u);
  EXPECT_FALSE(cleared[0].raised);
  EXPECT_EQ(cleared[0].monitor, "iplan-supervisor");
}

TEST(PermitGate, ARefusedSampleStillCountsAsAClaim) {
  PermitGate g = TwoMonitors();
  BothPermit(&g, kT0, kT0 + 200 * kMs);
  EXPECT_TRUE(g.OnPermit("iplan-collision_risk", kRogue, true, -1, "bad", kT0 + 160 * kMs, kT0 + 160 * kMs));
  const PermitDecision d = g.Evaluate(kT0 + 170 * kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("2 writers claim iplan-collision_risk"), std::string::npos) << d.reason;
}

TEST(PermitGate, OneWritersStopAndPermitCycleIsUnchanged) {
  PermitGate g = TwoMonitors();
  BothPermit(&g, kT0, kT0 + 100 * kMs);
  EXPECT_TRUE(g.Evaluate(kT0 + 60 * kMs).permitted);
  // The supervisor stops (valid 0.2 s) and resumes 50 ms later: its own
  // newer permit ends its stop at once.
  g.OnPermit("iplan-supervisor", kSup, false, 0.2, "deadline missed", kT0 + 100 * kMs, kT0 + 100 * kMs);
  g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", kT0 + 100 * kMs, kT0 + 100 * kMs);
  EXPECT_FALSE(g.Evaluate(kT0 + 120 * kMs).permitted);
  EXPECT_NE(g.Evaluate(kT0 + 120 * kMs).reason.find("iplan-supervisor stops: deadline missed"), std::string::npos);
  BothPermit(&g, kT0 + 150 * kMs, kT0 + 200 * kMs);
  EXPECT_TRUE(g.Evaluate(kT0 + 160 * kMs).permitted) << g.Evaluate(kT0 + 160 * kMs).reason;
  EXPECT_TRUE(g.TakeConflictEvents(kT0 + 160 * kMs).empty());
  // A stop that is not followed by a permit lapses like one (held, then lapsed).
  g.OnPermit("iplan-collision_risk", kRisk, false, 0.2, "too close", kT0 + 200 * kMs, kT0 + 200 * kMs);
  EXPECT_NE(g.Evaluate(kT0 + 399 * kMs).reason.find("iplan-collision_risk stops: too close"), std::string::npos);
  EXPECT_NE(g.Evaluate(kT0 + 400 * kMs).reason.find("permit from iplan-collision_risk lapsed"), std::string::npos);
  // And a replayed older stop is still honoured for what is left of it.
  BothPermit(&g, kT0 + 400 * kMs, kT0 + 500 * kMs);
  EXPECT_TRUE(g.Evaluate(kT0 + 460 * kMs).permitted);
  EXPECT_FALSE(g.OnPermit("iplan-supervisor", kSup, false, 0.2, "late stop", kT0 + 300 * kMs, kT0 + 460 * kMs));
  EXPECT_FALSE(g.Evaluate(kT0 + 470 * kMs).permitted);
  EXPECT_FALSE(g.Evaluate(kT0 + 549 * kMs).permitted);  // until 300 + 50 + 200 ms
  EXPECT_TRUE(g.Evaluate(kT0 + 550 * kMs).permitted) << g.Evaluate(kT0 + 550 * kMs).reason;
}

TEST(PermitGate, AMonitorRestartedWithANewWriterIsAcceptedAfterTheOldOneWasSilent) {
  PermitGate g = TwoMonitors();
  BothPermit(&g, kT0, kT0 + 1000 * kMs);  // supervisor writer kSup: last sample at 950 ms
  constexpr uint64_t kRestarted = 0x3333;
  // Restarted after 2.5 s (systemd): the old writer has been silent for more
  // than writer_silence, so the new one is the supervisor, no fault.
  for (int64_t t = kT0 + 1000 * kMs; t < kT0 + 3500 * kMs; t += 50 * kMs) {
    g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", t, t);
  }
  EXPECT_FALSE(g.Evaluate(kT0 + 3460 * kMs).permitted);  // lapsed meanwhile
  for (int64_t t = kT0 + 3500 * kMs; t < kT0 + 4000 * kMs; t += 50 * kMs) {
    ASSERT_FALSE(g.OnPermit("iplan-supervisor", kRestarted, true, 0.2, "healthy", t, t));
    g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", t, t);
  }
  EXPECT_TRUE(g.Evaluate(kT0 + 3960 * kMs).permitted) << g.Evaluate(kT0 + 3960 * kMs).reason;
  EXPECT_TRUE(g.TakeConflictEvents(kT0 + 3960 * kMs).empty());
  // A restart faster than writer_silence (new writer 0.5 s after the old
  // one's last sample) is reported as two writers and clears by itself 2 s
  // after the old writer's last sample.
  constexpr uint64_t kAgain = 0x4444;
  for (int64_t t = kT0 + 4500 * kMs; t < kT0 + 7000 * kMs; t += 50 * kMs) {
    g.OnPermit("iplan-supervisor", kAgain, true, 0.2, "healthy", t, t);
    g.OnPermit("iplan-collision_risk", kRisk, true, 0.2, "clear", t, t);
    const PermitDecision d = g.Evaluate(t + 10 * kMs);
    if (t + 10 * kMs < kT0 + 5950 * kMs) {  // kRestarted's last sample: 3950 ms
      EXPECT_FALSE(d.permitted) << "at " << (t - kT0) / kMs << " ms";
      EXPECT_NE(d.reason.find("writer 0000000000003333, writer 0000000000004444"), std::string::npos) << d.reason;
    } else {
      EXPECT_TRUE(d.permitted) << "at " << (t - kT0) / kMs << " ms: " << d.reason;
    }
  }
}

TEST(PermitGate, AFloodOfWriterIdentitiesStaysBoundedAndStopped) {
  PermitGate g = TwoMonitors();
  BothPermit(&g, kT0, kT0 + 100 * kMs);
  for (uint64_t id = 100; id < 10100; ++id) {
    g.OnPermit("iplan-supervisor", id, id % 2 == 0, 0.2, "flood", kT0 + 100 * kMs, kT0 + 100 * kMs);
  }
  const PermitDecision d = g.Evaluate(kT0 + 110 * kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("16 writers claim iplan-supervisor"), std::string::npos) << d.reason.substr(0, 200);
}

}  // namespace
}  // namespace iplan::safety
