// A Node is what a service sees of the system: typed publishers and
// subscriptions on catalogue topics, timers, one executor thread, and the
// diagnostics every service publishes.
//
// Every received message passes a boundary check before the callback sees
// it, in this order:
//  1. the writer: on a topic with entitled writers (the catalogue's, or the
//     `node.entitled_writers` configuration), samples from any other writer
//     are ignored, counted per topic as `ignored_writers`, logged once per
//     writer name, and reported in diagnostics;
//  2. the content: non-finite numbers, sizes beyond the limits, inconsistent
//     sizes (msg::Check), a header.frame_id other than the cell's frame on
//     topics in the cell frame;
//  3. time: a header stamp more than `max_stamp_ahead` ahead of this host's
//     clock (a forged or broken clock must not blind the cell), or older than
//     the previous accepted one from the same writer. One sample cannot
//     ratchet a writer's ordering: after kResyncAfter consecutive backwards
//     samples the writer's clock is taken to have stepped back and the
//     ordering restarts from the new stamp (logged).
// A failing message is rejected, counted per topic, logged once (then every
// 100th), and reported in diagnostics.
//
// A callback that throws is logged and counted; it never takes the service
// down.
//
// Readers accept what any writer offers, a ROS 2 default publisher included
// (no DEADLINE, infinite LIVELINESS lease, volatile): a reader that requested
// the topic's deadline or lease would not match such a writer at all. The
// node watches the topic's deadline itself instead: after the first accepted
// sample (one that passed the checks above, so a stranger or a broken writer
// cannot keep the topic fresh), every deadline period without one is a
// kDeadlineMissed event, as the DDS policy would report it. Liveliness of
// writers that offer the topic's lease (iplan's) is still reported by the
// reader (dds::QosProfile::watched_lease); a writer that offers none (ROS 2
// default) is watched by the deadline only.
//
// Threading: all callbacks and timers run on the thread that calls
// SpinOnce()/SpinUntil(); the core of a service therefore needs no locks.
//
// Fairness: one SpinOnce takes a subscription's samples only until its
// callbacks have run kDispatchSlice (at least one sample); what is left is
// taken in the next SpinOnce, which then does not wait, after the other
// ready subscriptions, the deadlines and the timers have had their turn. A
// topic whose callback is slower than its rate (30 Hz depth images at 35 ms
// each) would otherwise keep the executor to itself: the cloud service so
// starved its own joint states (every frame went without the self-filter)
// and its diagnostics timer.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <spdlog/logger.h>

#include "iplan/core/name_value.h"
#include "iplan/dds/participant.h"
#include "iplan/framework/topics.h"
#include "iplan/msg/check.h"
#include "iplan/msg/time.h"

namespace iplan::framework {

struct NodeOptions {
  double diagnostics_period = 1.0;  ///< s between diagnostics messages; 0: none
  std::string hardware_id;          ///< default: the host name
  /// s; header stamps further ahead of this host's clock are rejected
  /// (hosts are expected to be synchronised to well within this).
  double max_stamp_ahead = 0.5;
  /// The cell frame: header.frame_id of messages on topics in the cell frame.
  std::string frame_id = "world";
  /// Per topic (wire name "rt/..." or ROS name "/..."), the participant names
  /// whose samples are accepted; replaces the catalogue's list for that topic.
  /// An empty list accepts every writer.
  std::map<std::string, std::vector<std::string>> entitled_writers;
  /// SCHED_FIFO priority (1-99) of the service's threads; 0: the default
  /// scheduler. Needs LimitRTPRIO (systemd) or CAP_SYS_NICE; refused, the
  /// service says so and runs on the default scheduler.
  int realtime_priority = 0;
  /// Lock all memory (mlockall): no page faults on the executor. Needs
  /// LimitMEMLOCK=infinity or CAP_IPC_LOCK; refused, the service says so.
  bool lock_memory = false;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(diagnostics_period, "s between /diagnostics messages, >= 0; 0: none"));
    a->Visit(IPLAN_NVP(hardware_id, "diagnostics hardware_id; empty: the host name"));
    a->Visit(IPLAN_NVP(max_stamp_ahead, "s; header stamps further ahead of this host's clock are rejected, in [0, 60]"));
    a->Visit(IPLAN_NVP(frame_id, "the cell frame: header.frame_id of messages in the cell frame, not empty"));
    a->Visit(IPLAN_NVP(entitled_writers, "topic: [participant names] whose samples are accepted (replaces the catalogue's list; []: every writer)"));
    a->Visit(IPLAN_NVP(realtime_priority, "SCHED_FIFO priority of the service's threads, 0..99; 0: the default scheduler"));
    a->Visit(IPLAN_NVP(lock_memory, "lock all memory (mlockall); needs LimitMEMLOCK=infinity or CAP_IPC_LOCK"));
  }
  /// "" when valid, else the reason with the value.
  std::string Validate() const;
};

/// Section `node` of every service's file: the node's options (keys
/// inline) and the topic remappings.
struct NodeSettings {
  NodeOptions options;
  std::map<std::string, std::string> remap;  ///< topic name -> name on the wire

  template <class Archive>
  void Serialize(Archive* a) {
    options.Serialize(a);
    a->Visit(IPLAN_NVP(remap, "FROM: TO topic remappings (a leading '/' may be left out); --remap FROM:=TO rules over them"));
  }
  std::string Validate() const { return options.Validate(); }
};

/// Counters of one subscribed topic.
struct TopicStats {
  uint64_t received = 0;         ///< accepted and handed to the callback
  uint64_t rejected = 0;         ///< failed the boundary check
  uint64_t callback_errors = 0;  ///< callback threw
  uint64_t deadline_misses = 0;
  uint64_t liveliness_lost = 0;
  uint64_t incompatible_qos = 0;
  uint64_t ignored_writers = 0;  ///< samples from writers not entitled to the topic
  int alive_writers = 0;
  std::string last_rejection;
  std::string last_ignored_writer;  ///< name of the last writer ignored ("(unnamed)" when none)
};

struct SubscribeOptions {
  /// Reject a message whose header stamp is older than the previous accepted
  /// one from the same writer, or too far ahead of this host's clock.
  bool check_stamps = true;
};

/// Consecutive backwards samples from one writer after which its ordering
/// restarts from the newest stamp (a clock stepped back, not a reordering).
constexpr int kResyncAfter = 3;

class Node {
 public:
  /// How long one SpinOnce lets a subscription's callbacks run before the
  /// rest of its samples wait for the next (file comment, "Fairness").
  static constexpr std::chrono::milliseconds kDispatchSlice{5};
  /// Throws std::runtime_error when the diagnostics writer cannot be created.
  Node(std::string name, dds::Participant& participant, NodeOptions options = {});
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  /// A writer for `topic`, owned by the node. Call from the executor thread
  /// or before spinning. Throws std::runtime_error on vendor errors.
  template <class T>
  dds::Writer<T>& Advertise(const Topic<T>& topic);

  /// Calls `on_message` for every accepted message on `topic`.
  template <class T>
  void Subscribe(const Topic<T>& topic,
                 std::function<void(const T&, const dds::SampleInfo&)> on_message,
                 SubscribeOptions options = {});

  /// Called for every deadline, liveliness and matching event of every
  /// subscription (after the node has counted and logged it).
  void OnReaderEvent(std::function<void(const std::string& topic, const dds::ReaderEvent&)> cb) {
    on_event_ = std::move(cb);
  }

  /// Runs `cb` every `period` (first call one period from now). Returns an id.
  int AddTimer(std::chrono::nanoseconds period, std::function<void()> cb);
  void CancelTimer(int id);

  /// Waits at most `max_wait` for messages, events or a due timer, and runs
  /// what is ready.
  void SpinOnce(std::chrono::nanoseconds max_wait);
  /// Spins until `stop()` is true (checked at least every 50 ms); calls
  /// `on_idle` after every SpinOnce (e.g. systemd watchdog).
  void SpinUntil(const std::function<bool()>& stop, const std::function<void()>& on_idle = nullptr);

  /// Counts an input that a service's core refused after the boundary check
  /// (unknown joint names, inconsistent content): no-op when `rejection` is
  /// empty; else counted in diagnostics as `rejected_inputs/<input>`, logged
  /// the first time and every 100th. Returns true when it was a rejection.
  bool CountRejection(const std::string& input, const std::optional<std::string>& rejection);

  /// Processing time of one cycle of the service's main loop, s.
  void RecordCycleTime(double seconds);
  /// Lifecycle state shown in diagnostics ("configured", "active", ...).
  void SetState(const std::string& state, uint8_t level = msg::DiagnosticStatus::OK);
  /// Adds a service-specific value to every diagnostics message.
  void SetDiagnosticValue(const std::string& key, const std::string& value);
  /// Publishes diagnostics now (also done every diagnostics_period).
  void PublishDiagnostics();
  msg::DiagnosticArray MakeDiagnostics() const;

  /// Counters of a subscribed topic (zeros when not subscribed).
  TopicStats stats(const std::string& topic) const;
  /// Entitled writers of `topic` after the configuration (empty: anyone).
  std::vector<std::string> EntitledWriters(const std::string& topic,
                                           const std::vector<std::string>& catalogue) const;
  spdlog::logger& log() { return *log_; }
  const std::string& name() const { return name_; }
  dds::Participant& participant() { return participant_; }

 private:
  struct SubscriptionBase {
    virtual ~SubscriptionBase() = default;
    /// Takes and handles samples until none is left (false) or the
    /// callbacks have run for kDispatchSlice (true: there may be more).
    virtual bool Dispatch(Node& node) = 0;
    std::unique_ptr<dds::AnyReader> reader;
    TopicStats stats;
    SubscribeOptions options;
    std::vector<std::string> entitled;  // empty: anyone
    bool check_frame = false;
    struct WriterClock {
      int64_t last_ns = 0;
      int backwards = 0;  // consecutive backwards samples
    };
    // The topic's deadline, watched here (see the file comment).
    std::chrono::nanoseconds deadline{0};
    std::optional<std::chrono::steady_clock::time_point> last_sample;  // any sample taken
    int missed_periods = 0;  // since the last sample
    int32_t deadline_misses_total = 0;
    std::map<uint64_t, WriterClock> clocks;  // per writer
    std::set<std::string> ignored_names;     // logged once each
  };
  template <class T>
  struct Subscription;
  struct Timer {
    std::chrono::nanoseconds period;
    std::chrono::steady_clock::time_point next;
    std::function<void()> cb;
  };

  void HandleEvents(SubscriptionBase& sub);
  /// Counts, logs and passes on (on_event_) one event of `sub`: the reader's,
  /// or a deadline miss the node found (CheckDeadlines).
  void HandleEvent(SubscriptionBase& sub, const dds::ReaderEvent& e);
  /// Emits the deadline misses due by now; returns the time of the next one.
  std::optional<std::chrono::steady_clock::time_point> CheckDeadlines();
  void Reject(SubscriptionBase& sub, const std::string& why);
  /// True when the writer may write this topic (else counts and logs it).
  bool AcceptWriter(SubscriptionBase& sub, const dds::SampleInfo& info);
  /// True when the frame is the cell's (or the topic is not in it).
  bool AcceptFrame(SubscriptionBase& sub, const std::string& frame_id);
  /// True when the stamp is acceptable for this writer (and records it).
  bool AcceptStamp(SubscriptionBase& sub, uint64_t writer, int64_t stamp_ns);

  template <class F>
  void RunGuarded(SubscriptionBase* sub, const char* what, F&& f);
  void RunTimers();

  std::string name_;
  dds::Participant& participant_;
  NodeOptions options_;
  std::shared_ptr<spdlog::logger> log_;
  std::map<std::string, std::unique_ptr<dds::AnyWriter>> writers_;
  std::vector<std::unique_ptr<SubscriptionBase>> subscriptions_;
  std::map<const dds::AnyReader*, SubscriptionBase*> by_reader_;
  std::map<int, Timer> timers_;
  int next_timer_id_ = 1;
  std::function<void(const std::string&, const dds::ReaderEvent&)> on_event_;
  std::vector<dds::AnyReader*> ready_;
  std::vector<SubscriptionBase*> backlog_;  // cut short by kDispatchSlice in the last SpinOnce
  std::vector<SubscriptionBase*> due_;      // this SpinOnce's, kept to reuse its buffer
  // Diagnostics state.
  std::string state_ = "unconfigured";
  uint8_t level_ = msg::DiagnosticStatus::OK;
  std::map<std::string, std::string> extra_values_;
  std::map<std::string, uint64_t> core_rejections_;
  std::deque<double> cycle_times_;
  dds::Writer<msg::DiagnosticArray>* diagnostics_writer_ = nullptr;
};

// ---------------------------------------------------------------------------

template <class T>
dds::Writer<T>& Node::Advertise(const Topic<T>& topic) {
  auto it = writers_.find(topic.name);
  if (it == writers_.end()) {
    it = writers_.emplace(topic.name, std::make_unique<dds::Writer<T>>(participant_, topic.name, topic.qos)).first;
  }
  return static_cast<dds::Writer<T>&>(*it->second);
}

template <class T>
struct Node::Subscription : Node::SubscriptionBase {
  std::function<void(const T&, const dds::SampleInfo&)> on_message;
  T msg;  // reused buffer
  bool Dispatch(Node& node) override {
    auto* r = static_cast<dds::Reader<T>*>(reader.get());
    dds::SampleInfo info;
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
      if (std::chrono::steady_clock::now() - start >= kDispatchSlice) return true;
      bool took = false;
      try {
        took = r->Take(&msg, &info);
      } catch (const std::exception& e) {
        node.Reject(*this, std::string("cannot convert sample: ") + e.what());
        continue;
      }
      if (!took) return false;
      if (!node.AcceptWriter(*this, info)) continue;
      if (auto why = msg::Check(msg)) {
        node.Reject(*this, *why);
        continue;
      }
      if constexpr (msg::HasHeader<T>::value) {
        if (!node.AcceptFrame(*this, msg.header.frame_id)) continue;
        if (options.check_stamps &&
            !node.AcceptStamp(*this, info.writer_id, msg::ToNanoseconds(msg.header.stamp))) {
          continue;
        }
      }
      ++stats.received;
      last_sample = std::chrono::steady_clock::now();
      missed_periods = 0;
      node.RunGuarded(this, "callback", [&] { on_message(msg, info); });
    }
  }
};

template <class T>
void Node::Subscribe(const Topic<T>& topic, std::function<void(const T&, const dds::SampleInfo&)> on_message,
                     SubscribeOptions options) {
  auto sub = std::make_unique<Subscription<T>>();
  sub->on_message = std::move(on_message);
  sub->options = options;
  sub->entitled = EntitledWriters(topic.name, topic.writers);
  sub->check_frame = topic.in_cell_frame;
  sub->deadline = topic.qos.deadline;
  sub->reader = std::make_unique<dds::Reader<T>>(participant_, topic.name, topic.qos.AcceptingAnyWriter());
  by_reader_[sub->reader.get()] = sub.get();
  subscriptions_.push_back(std::move(sub));
}

template <class F>
void Node::RunGuarded(SubscriptionBase* sub, const char* what, F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    if (sub) ++sub->stats.callback_errors;
    log_->error("{} {} threw: {}", sub ? sub->reader->topic() : std::string("timer"), what, e.what());
  }
}

}  // namespace iplan::framework
