#include "iplan/safety/permit_gate.h"

#include <gtest/gtest.h>

namespace iplan::safety {
namespace {

constexpr int64_t kMs = 1000000;
constexpr int64_t kT0 = 1700000000000 * kMs;  // an arbitrary wall-clock time

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
  ASSERT_FALSE(g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0, kT0));
  EXPECT_FALSE(g.Evaluate(kT0).permitted);
  EXPECT_NE(g.Evaluate(kT0).reason.find("iplan-collision_risk"), std::string::npos);
  ASSERT_FALSE(g.OnPermit("iplan-collision_risk", true, 0.2, "clear", kT0, kT0));
  EXPECT_TRUE(g.Evaluate(kT0 + 100 * kMs).permitted);
}

TEST(PermitGate, OneStopIsEnough) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", false, 0.2, "separation below S_p", kT0, kT0);
  const PermitDecision d = g.Evaluate(kT0 + kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("iplan-collision_risk stops: separation below S_p"), std::string::npos) << d.reason;
}

TEST(PermitGate, APermitLapsesAfterItsValidity) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", true, 0.2, "clear", kT0, kT0);
  EXPECT_TRUE(g.Evaluate(kT0 + 199 * kMs).permitted);
  const PermitDecision d = g.Evaluate(kT0 + 200 * kMs);
  EXPECT_FALSE(d.permitted);
  EXPECT_NE(d.reason.find("lapsed"), std::string::npos) << d.reason;
}

TEST(PermitGate, AMonitorCannotGrantMoreThanTheRobotAllows) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", true, 5.0, "healthy", kT0, kT0);
  g.OnPermit("iplan-collision_risk", true, 5.0, "clear", kT0, kT0);
  EXPECT_TRUE(g.Evaluate(kT0 + 249 * kMs).permitted);
  EXPECT_FALSE(g.Evaluate(kT0 + 250 * kMs).permitted);  // max_validity 0.25 s
}

TEST(PermitGate, ADelayedPermitLapsesEarly) {
  PermitGate g = TwoMonitors();
  // Stamped 150 ms before it arrives (replayed or held up): it is good only
  // until stamp + tolerance + validity = kT0 + 50 ms + 200 ms.
  g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0, kT0 + 150 * kMs);
  g.OnPermit("iplan-collision_risk", true, 0.2, "clear", kT0 + 150 * kMs, kT0 + 150 * kMs);
  EXPECT_TRUE(g.Evaluate(kT0 + 249 * kMs).permitted);
  EXPECT_FALSE(g.Evaluate(kT0 + 250 * kMs).permitted);
}

TEST(PermitGate, AForgedClockBuysNoTime) {
  PermitGate g = TwoMonitors();
  const auto why = g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0 + 3600000 * kMs, kT0);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("ahead of this clock"), std::string::npos) << *why;
  EXPECT_FALSE(g.Evaluate(kT0).permitted);
  // And a refused future permit does not block the real ones after it.
  EXPECT_FALSE(g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0 + 10 * kMs, kT0 + 10 * kMs));
  EXPECT_FALSE(g.OnPermit("iplan-collision_risk", true, 0.2, "clear", kT0 + 10 * kMs, kT0 + 10 * kMs));
  EXPECT_TRUE(g.Evaluate(kT0 + 20 * kMs).permitted);
}

TEST(PermitGate, AnOlderPermitIsRefused) {
  PermitGate g = TwoMonitors();
  g.OnPermit("iplan-supervisor", false, 0.2, "deadline missed", kT0 + 100 * kMs, kT0 + 100 * kMs);
  g.OnPermit("iplan-collision_risk", true, 0.2, "clear", kT0 + 100 * kMs, kT0 + 100 * kMs);
  // A replay of an earlier PERMIT must not lift the newer STOP.
  const auto why = g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0, kT0 + 110 * kMs);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("older than the permit held"), std::string::npos);
  EXPECT_FALSE(g.Evaluate(kT0 + 120 * kMs).permitted);
}

TEST(PermitGate, StrangersAreRefused) {
  PermitGate g = TwoMonitors();
  const auto why = g.OnPermit("rogue", true, 0.2, "trust me", kT0, kT0);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("not a configured monitor"), std::string::npos);
  EXPECT_FALSE(g.OnPermit("iplan-supervisor", true, 0.2, "healthy", kT0, kT0));
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
}

}  // namespace
}  // namespace iplan::safety
