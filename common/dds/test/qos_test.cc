// The reader side that accepts a ROS 2 default publisher
// (QosProfile::AcceptingAnyWriter) and the consistency rules of the watched
// lease.
#include <gtest/gtest.h>

#include "iplan/dds/qos.h"

namespace iplan::dds {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

TEST(Qos, AcceptingAnyWriterRequestsNothingARos2DefaultPublisherLacks) {
  for (const QosProfile& p : {QosProfile::SensorStream(milliseconds(100), milliseconds(300)),
                              QosProfile::LatchedState(milliseconds(300), milliseconds(300)),
                              QosProfile::Command(milliseconds(1000))}) {
    const QosProfile r = p.AcceptingAnyWriter();
    EXPECT_EQ(r.deadline, nanoseconds(0)) << p.name;
    EXPECT_EQ(r.liveliness_lease, nanoseconds(0)) << p.name;
    EXPECT_EQ(r.durability, QosProfile::Durability::kVolatile) << p.name;
    EXPECT_EQ(r.reader_reliability, p.reader_reliability) << p.name;
    EXPECT_EQ(r.depth, p.depth) << p.name;
    // The liveliness of writers offering the topic's lease is still watched.
    EXPECT_EQ(r.watched_lease, p.liveliness_lease) << p.name;
    EXPECT_EQ(r.Validate(), "") << p.name;
  }
}

TEST(Qos, AWatchedLeaseIsOnlyForReadersWithAnInfiniteOne) {
  QosProfile q = QosProfile::SensorStream(milliseconds(100), milliseconds(300));
  q.watched_lease = milliseconds(300);
  EXPECT_EQ(q.Validate(), "a watched lease is for readers that request an infinite lease");
  q.liveliness_lease = nanoseconds(0);
  EXPECT_EQ(q.Validate(), "");
  q.watched_lease = nanoseconds(-1);
  EXPECT_EQ(q.Validate(), "watched lease must not be negative");
}

}  // namespace
}  // namespace iplan::dds
