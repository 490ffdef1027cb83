// Named QoS profiles. Every iplan topic uses one of three profiles, each with
// the topic's own DEADLINE period and LIVELINESS lease (see docs/topics.md).
//
// Writers offer what readers request (DDS request/offer matching): a writer's
// deadline must be <= the reader's, its lease <= the reader's, its reliability
// and durability >= the reader's. Using one profile on both sides of a topic
// always matches; tools that only watch a topic use Relaxed().
#pragma once

#include <chrono>
#include <string>

namespace iplan::dds {

struct QosProfile {
  enum class Reliability { kBestEffort, kReliable };
  enum class Durability { kVolatile, kTransientLocal };

  std::string name;  ///< "sensor", "state", "command" or "relaxed"
  Reliability writer_reliability = Reliability::kReliable;
  Reliability reader_reliability = Reliability::kReliable;
  Durability durability = Durability::kVolatile;
  int depth = 10;  ///< KEEP_LAST depth, >= 1
  /// DEADLINE period; zero: no deadline. A reader is told of every period
  /// without a sample from a writer (EventKind::kDeadlineMissed).
  std::chrono::nanoseconds deadline{0};
  /// AUTOMATIC liveliness lease; zero: infinite. A writer process that dies
  /// is reported as EventKind::kLivelinessLost within about one lease.
  std::chrono::nanoseconds liveliness_lease{0};
  /// Reader only, with an infinite `liveliness_lease`: the reader still
  /// reports liveliness lost/regained of the writers that offer this lease
  /// or a shorter one (iplan's own), while it matches writers that offer
  /// none (a ROS 2 default publisher). Zero: off. Cyclone tracks every
  /// writer's own lease anyway; a Fast DDS 2.9 reader with an infinite lease
  /// tracks none, so the Fast DDS backend adds a second, data-less reader
  /// that requests this lease (docs/dds.md, "Readers that accept ROS 2").
  std::chrono::nanoseconds watched_lease{0};

  /// Sensor streams (skeletons, predictions, joint states, risk): writers
  /// reliable, readers best-effort (so a reader also accepts a best-effort
  /// third-party sensor), volatile, keep last 5.
  static QosProfile SensorStream(std::chrono::nanoseconds deadline,
                                 std::chrono::nanoseconds lease);
  /// Latched state (the executing trajectory, safety commands): reliable,
  /// transient-local, keep last 1; late joiners get the last sample.
  static QosProfile LatchedState(std::chrono::nanoseconds deadline,
                                 std::chrono::nanoseconds lease);
  /// Commands and outcomes: reliable, volatile, keep last 10; never replayed.
  static QosProfile Command(std::chrono::nanoseconds lease);
  /// A reader that matches any writer: best-effort, volatile, no deadline,
  /// infinite lease. For tools.
  static QosProfile Relaxed();
  /// The same profile with the reader's durability raised to transient-local
  /// when the writer's profile is latched (for tools echoing a latched topic).
  QosProfile RelaxedFor() const;
  /// The reader side that matches every writer this profile's writers would,
  /// and a ROS 2 default publisher too: the reader's reliability, no
  /// deadline, infinite lease, volatile (a late joiner waits for the next
  /// sample); liveliness of writers offering this profile's lease is still
  /// reported (`watched_lease`). The caller watches the deadline itself
  /// (framework::Node).
  QosProfile AcceptingAnyWriter() const;

  /// Empty when the profile is consistent, else the reason.
  std::string Validate() const;
};

}  // namespace iplan::dds
