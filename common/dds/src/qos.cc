#include "iplan/dds/qos.h"

namespace iplan::dds {

QosProfile QosProfile::SensorStream(std::chrono::nanoseconds deadline, std::chrono::nanoseconds lease) {
  QosProfile q;
  q.name = "sensor";
  q.writer_reliability = Reliability::kReliable;
  q.reader_reliability = Reliability::kBestEffort;
  q.durability = Durability::kVolatile;
  q.depth = 5;
  q.deadline = deadline;
  q.liveliness_lease = lease;
  return q;
}

QosProfile QosProfile::LatchedState(std::chrono::nanoseconds deadline, std::chrono::nanoseconds lease) {
  QosProfile q;
  q.name = "state";
  q.writer_reliability = q.reader_reliability = Reliability::kReliable;
  q.durability = Durability::kTransientLocal;
  q.depth = 1;
  q.deadline = deadline;
  q.liveliness_lease = lease;
  return q;
}

QosProfile QosProfile::Command(std::chrono::nanoseconds lease) {
  QosProfile q;
  q.name = "command";
  q.writer_reliability = q.reader_reliability = Reliability::kReliable;
  q.durability = Durability::kVolatile;
  q.depth = 10;
  q.liveliness_lease = lease;
  return q;
}

QosProfile QosProfile::Relaxed() {
  QosProfile q;
  q.name = "relaxed";
  q.writer_reliability = Reliability::kReliable;
  q.reader_reliability = Reliability::kBestEffort;
  q.durability = Durability::kVolatile;
  q.depth = 100;
  return q;
}

QosProfile QosProfile::AcceptingAnyWriter() const {
  QosProfile q = *this;
  q.deadline = std::chrono::nanoseconds(0);
  q.watched_lease = liveliness_lease;
  q.liveliness_lease = std::chrono::nanoseconds(0);
  q.durability = Durability::kVolatile;
  return q;
}

QosProfile QosProfile::RelaxedFor() const {
  QosProfile q = Relaxed();
  if (durability == Durability::kTransientLocal) {
    // A transient-local reader needs a reliable, transient-local writer.
    q.durability = Durability::kTransientLocal;
    q.reader_reliability = Reliability::kReliable;
  }
  return q;
}

std::string QosProfile::Validate() const {
  if (depth < 1) return "depth " + std::to_string(depth) + " must be >= 1";
  if (deadline.count() < 0) return "deadline must not be negative";
  if (liveliness_lease.count() < 0) return "liveliness lease must not be negative";
  if (watched_lease.count() < 0) return "watched lease must not be negative";
  if (watched_lease.count() > 0 && liveliness_lease.count() > 0) {
    return "a watched lease is for readers that request an infinite lease";
  }
  if (writer_reliability == Reliability::kBestEffort && reader_reliability == Reliability::kReliable) {
    return "a reliable reader never matches a best-effort writer";
  }
  return "";
}

}  // namespace iplan::dds
