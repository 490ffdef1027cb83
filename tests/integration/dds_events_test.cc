// Status events across processes: kill -9 of a writer is reported as
// liveliness loss within its lease; a writer that stops publishing is
// reported as a deadline miss; malformed samples are rejected and counted by
// the framework without reaching the callback. All four vendor pairings.
#include <signal.h>

#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "iplan/dds/participant.h"
#include "iplan/framework/node.h"
#include "iplan/framework/topics.h"
#include "test_paths.h"
#include "vendor_pairings.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;


class DdsEvents : public ::testing::TestWithParam<Pairing> {
 protected:
  std::unique_ptr<dds::Participant> MakeParticipant(int domain) {
    dds::ParticipantOptions o;
    o.vendor = dds::ParseVendor(GetParam().reader);
    o.domain_id = domain;
    o.name = "events_test";
    return dds::Participant::Create(o);
  }
  // A node without the diagnostics timer (this test's timers are its own).
  static std::unique_ptr<framework::Node> QuietNode(const std::string& name, dds::Participant& p) {
    framework::NodeOptions opts;
    opts.diagnostics_period = 0;
    return std::make_unique<framework::Node>(name, p, opts);
  }
  int Domain(int k) {
    return UniqueDomain(k * 11 + static_cast<int>(GetParam().writer.size() * 3 + GetParam().reader.size()));
  }
  std::unique_ptr<Process> Stream(int domain, const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {TestBinPath("dds_probe"), "stream", "--dds", GetParam().writer,
                                     "--domain", std::to_string(domain)};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<Process>(argv);
  }
};

// Waits on the participant until `pred(events)` returns true or timeout.
template <class Pred>
bool WaitForEvent(dds::Participant& p, dds::AnyReader& r, Clock::duration timeout, Pred pred,
                  int* samples = nullptr) {
  const auto end = Clock::now() + timeout;
  std::vector<dds::AnyReader*> ready;
  msg::HumanSkeleton s;
  dds::SampleInfo info;
  while (Clock::now() < end) {
    p.Wait(20ms, &ready);
    for (const auto& e : r.TakeEvents()) {
      if (pred(e)) return true;
    }
    while (r.TakeAny(&s, &info)) {
      if (samples) ++*samples;
    }
  }
  return false;
}

// The reader accepts any writer, as a node's readers do (no requested
// lease, framework/node.h): liveliness of writers offering the topic's lease
// is still reported (Cyclone tracks the writer's own lease; on Fast DDS a
// second, data-less reader requests it: QosProfile::watched_lease).
TEST_P(DdsEvents, KillNineIsReportedAsLivelinessLossWithinLease) {
  const int domain = Domain(1);
  auto p = MakeParticipant(domain);
  const auto topic = framework::topics::HumanSkeleton();
  dds::Reader<msg::HumanSkeleton> reader(*p, topic.name, topic.qos.AcceptingAnyWriter());
  auto writer = Stream(domain, {"--rate", "30"});
  int samples = 0;
  ASSERT_TRUE(WaitForEvent(*p, reader, 20s, [](const dds::ReaderEvent& e) {
    return e.kind == dds::EventKind::kLivelinessRegained;
  }, &samples)) << writer->Stderr();
  ASSERT_TRUE(writer->WaitForOutput("publishing", 10s));
  std::this_thread::sleep_for(300ms);
  const auto killed = Clock::now();
  writer->Signal(SIGKILL);
  ASSERT_TRUE(WaitForEvent(*p, reader, 5s, [](const dds::ReaderEvent& e) {
    return e.kind == dds::EventKind::kLivelinessLost;
  }));
  const double seconds = std::chrono::duration<double>(Clock::now() - killed).count();
  const double lease = std::chrono::duration<double>(topic.qos.liveliness_lease).count();
  RecordProperty("liveliness_loss_detected_after_s", std::to_string(seconds));
  std::cout << "liveliness loss reported " << seconds << " s after kill -9 (lease " << lease << " s)\n";
  // Within the lease, plus 100 ms for the executor's wake-up on a busy 2-core machine.
  EXPECT_LE(seconds, lease + 0.1);
}

TEST_P(DdsEvents, WriterThatStopsPublishingIsReportedAsDeadlineMiss) {
  const int domain = Domain(2);
  auto p = MakeParticipant(domain);
  const auto topic = framework::topics::HumanSkeleton();
  dds::Reader<msg::HumanSkeleton> reader(*p, topic.name, topic.qos);
  auto writer = Stream(domain, {"--rate", "30", "--publish-for", "1.5", "--duration", "20"});
  int misses_while_publishing = 0;
  int samples = 0;
  ASSERT_TRUE(writer->WaitForOutput("publishing", 20s)) << writer->Stderr();
  // While the writer publishes at 30 Hz, a 150 ms deadline is met.
  const auto until_pause = Clock::now() + 1200ms;
  WaitForEvent(*p, reader, until_pause - Clock::now(), [&](const dds::ReaderEvent& e) {
    if (e.kind == dds::EventKind::kDeadlineMissed && samples > 0) misses_while_publishing += e.count_change;
    return false;
  }, &samples);
  EXPECT_GT(samples, 20);
  EXPECT_EQ(misses_while_publishing, 0);
  ASSERT_TRUE(writer->WaitForOutput("paused", 5s))
      << "the writer " << (writer->Running() ? "is still running" : "exited with " + std::to_string(*writer->Wait(0ms)))
      << "; its stdout:\n" << writer->Stdout() << "its stderr:\n" << writer->Stderr();
  const auto paused = Clock::now();
  ASSERT_TRUE(WaitForEvent(*p, reader, 3s, [](const dds::ReaderEvent& e) {
    return e.kind == dds::EventKind::kDeadlineMissed;
  }));
  const double seconds = std::chrono::duration<double>(Clock::now() - paused).count();
  std::cout << "deadline miss reported " << seconds << " s after the writer paused\n";
  EXPECT_LE(seconds, 2 * std::chrono::duration<double>(topic.qos.deadline).count() + 0.1);
  // The writer is still alive: no liveliness loss.
  int lost = 0;
  WaitForEvent(*p, reader, 500ms, [&](const dds::ReaderEvent& e) {
    if (e.kind == dds::EventKind::kLivelinessLost) ++lost;
    return false;
  });
  EXPECT_EQ(lost, 0);
}

// A publisher with ROS 2's default QoS (no deadline, infinite lease,
// volatile) matches the cell's readers (a reader that requested the topic's
// deadline or lease would not match it), and the node still reports its
// silence as deadline misses, within the topic's deadline.
TEST_P(DdsEvents, Ros2DefaultPublisherMatchesAndItsSilenceIsADeadlineMiss) {
  const int domain = Domain(5);
  auto p = MakeParticipant(domain);
  auto owned = QuietNode("ros2_compat_test", *p);
  framework::Node& node = *owned;
  const auto topic = framework::topics::HumanSkeleton();
  int callbacks = 0;
  std::optional<Clock::time_point> first_miss;
  Clock::time_point paused{};
  bool is_paused = false;
  node.Subscribe(topic, std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                            [&](const msg::HumanSkeleton&, const dds::SampleInfo&) { ++callbacks; }));
  node.OnReaderEvent([&](const std::string&, const dds::ReaderEvent& e) {
    if (e.kind == dds::EventKind::kDeadlineMissed && is_paused && !first_miss) first_miss = Clock::now();
  });
  auto writer = Stream(domain, {"--rate", "30", "--publish-for", "1.5", "--duration", "20", "--ros2-default-qos"});
  ASSERT_TRUE(writer->WaitForOutput("publishing", 20s)) << writer->Stderr();
  const auto end = Clock::now() + 10s;
  while (Clock::now() < end && !first_miss) {
    node.SpinOnce(5ms);
    if (!is_paused && writer->Stdout().find("paused") != std::string::npos) {
      is_paused = true;
      paused = Clock::now();
    }
  }
  const framework::TopicStats st = node.stats(topic.name);
  EXPECT_EQ(st.incompatible_qos, 0u);
  EXPECT_GT(callbacks, 20) << "the ROS 2 default publisher did not reach the node";
  ASSERT_TRUE(first_miss.has_value()) << "no deadline miss after the publisher fell silent";
  const double seconds = std::chrono::duration<double>(*first_miss - paused).count();
  std::cout << "deadline miss reported " << seconds << " s after a ROS 2 default publisher paused\n";
  EXPECT_LE(seconds, std::chrono::duration<double>(topic.qos.deadline).count() + 0.1);
  EXPECT_GT(st.deadline_misses, 0u);
}

struct Counts {
  int published = 0;
  framework::TopicStats stats;
  int callbacks = 0;
  std::string diagnostics_rejected;
};

Counts RunMalformed(DdsEvents& t, dds::Participant& p, Process& writer) {
  Counts c;
  framework::NodeOptions opts;
  opts.diagnostics_period = 0;
  framework::Node node("malformed_test", p, opts);
  const auto topic = framework::topics::HumanSkeleton();
  int64_t last_stamp = 0;
  bool backwards_seen = false;
  node.Subscribe(topic, std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                            [&](const msg::HumanSkeleton& s, const dds::SampleInfo&) {
                              ++c.callbacks;
                              const int64_t ns = msg::ToNanoseconds(s.header.stamp);
                              if (ns < last_stamp) backwards_seen = true;
                              last_stamp = ns;
                              for (const auto& j : s.joints) {
                                if (!std::isfinite(j.position.x)) throw std::logic_error("NaN reached the callback");
                              }
                            }));
  const auto end = Clock::now() + 20s;
  while (writer.Running() && Clock::now() < end) node.SpinOnce(20ms);
  for (int i = 0; i < 10; ++i) node.SpinOnce(20ms);
  const std::string out = writer.Stdout();
  const auto pos = out.rfind("published ");
  if (pos != std::string::npos) c.published = std::stoi(out.substr(pos + 10));
  c.stats = node.stats(topic.name);
  const msg::DiagnosticArray diagnostics = node.MakeDiagnostics();
  for (const auto& kv : diagnostics.status.at(0).values) {
    if (kv.key == "rejected/" + topic.name) c.diagnostics_rejected = kv.value;
  }
  EXPECT_FALSE(backwards_seen) << "a stamp going backwards reached the callback";
  return c;
}

TEST_P(DdsEvents, NanSkeletonsAreRejectedAndCounted) {
  const int domain = Domain(3);
  auto p = MakeParticipant(domain);
  auto writer = Stream(domain, {"--rate", "50", "--duration", "1.5", "--mode", "nan"});
  Counts c = RunMalformed(*this, *p, *writer);
  EXPECT_GT(c.published, 40);
  EXPECT_EQ(c.callbacks, 0);
  EXPECT_EQ(c.stats.received, 0u);
  EXPECT_EQ(c.stats.callback_errors, 0u);
  // Loopback best-effort: at most the first sample before matching can be lost.
  EXPECT_GE(static_cast<int>(c.stats.rejected), c.published - 2);
  EXPECT_LE(static_cast<int>(c.stats.rejected), c.published);
  EXPECT_EQ(c.diagnostics_rejected, std::to_string(c.stats.rejected));
  EXPECT_EQ(c.stats.last_rejection, "non-finite number at joints[5].position.x");
}

TEST_P(DdsEvents, BackwardsStampsAndWrongSizesAreRejected) {
  const int domain = Domain(4);
  auto p = MakeParticipant(domain);
  {
    auto writer = Stream(domain, {"--rate", "50", "--duration", "1.5", "--mode", "backwards"});
    Counts c = RunMalformed(*this, *p, *writer);
    EXPECT_GT(c.published, 40);
    // Every other message is stamped one second in the past.
    EXPECT_NEAR(static_cast<double>(c.stats.rejected), c.published / 2.0, 2.0);
    EXPECT_NEAR(static_cast<double>(c.stats.received), c.published / 2.0, 2.0);
    EXPECT_NE(c.stats.last_rejection.find("stamp went backwards"), std::string::npos) << c.stats.last_rejection;
  }
  {
    auto writer = Stream(domain, {"--rate", "50", "--duration", "1.0", "--mode", "wrong-size"});
    Counts c = RunMalformed(*this, *p, *writer);
    EXPECT_EQ(c.stats.received, 0u);
    EXPECT_GE(static_cast<int>(c.stats.rejected), c.published - 2);
    EXPECT_EQ(c.stats.last_rejection, "skeleton has no joints");
  }
}

// A topic whose callback is slower than its rate does not keep the node's
// executor to itself (Node, "Fairness"): skeletons at 100 Hz, each callback
// 20 ms, and a 50 ms timer beside them. Before, the subscription's samples
// were taken until none was left, which never happened, and the timer (as
// the cloud service's diagnostics and its joint states with 30 Hz depth
// images) did not run at all.
TEST_P(DdsEvents, ASlowCallbackDoesNotStarveTimers) {
  const int domain = Domain(6);
  auto p = MakeParticipant(domain);
  auto owned = QuietNode("fairness_test", *p);
  framework::Node& node = *owned;
  int callbacks = 0, ticks = 0;
  node.Subscribe(framework::topics::HumanSkeleton(),
                 std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                     [&](const msg::HumanSkeleton&, const dds::SampleInfo&) {
                       ++callbacks;
                       std::this_thread::sleep_for(20ms);
                     }));
  auto writer = Stream(domain, {"--rate", "100", "--duration", "6"});
  // Until the stream is flowing (each SpinOnce returns after a slice; before,
  // the first one returned only when the 6 s stream ended), then 2 s with
  // the timer.
  const auto flowing_by = Clock::now() + 10s;
  const auto spin_limit = 1s;
  while (callbacks < 5 && Clock::now() < flowing_by) {
    const auto t0 = Clock::now();
    node.SpinOnce(20ms);
    ASSERT_LT(Clock::now() - t0, spin_limit) << "one SpinOnce held the executor for " << callbacks << " callbacks";
  }
  ASSERT_GE(callbacks, 5) << "the stream did not reach the node";
  node.AddTimer(50ms, [&] { ++ticks; });
  const int before = callbacks;
  const auto end = Clock::now() + 2s;
  while (Clock::now() < end) node.SpinOnce(20ms);
  // 2 s of 20 ms callbacks and 50 ms ticks: about 40 of each share the time.
  EXPECT_GE(ticks, 20) << callbacks - before << " callbacks meanwhile";
  EXPECT_GE(callbacks - before, 40);
}

INSTANTIATE_TEST_SUITE_P(AllPairings, DdsEvents, AllVendorPairings(), PairingName);

}  // namespace
}  // namespace iplan::testing
