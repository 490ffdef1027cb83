// The plain Fast DDS type supports (fastdds_plain_type.h) against fastddsgen's
// PubSubTypes: same names, sizes and key handling, byte-identical samples in
// both directions for every type, both endiannesses read, and bad samples
// rejected (counted) without a crash.
#include <cstring>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "fastdds_convert.h"
#include "fastdds_plain_type.h"
#include "iplan/msg/type_table.h"

namespace iplan::dds {
namespace {

using Payload = eprosima::fastrtps::rtps::SerializedPayload_t;
using eprosima::fastcdr::Cdr;
using eprosima::fastdds::dds::TopicDataType;

constexpr int kSamplesPerType = 25;

const fastdds_gen::FastTypeOps& GeneratedOps(const std::string& name) {
  for (const auto& o : fastdds_gen::AllFastTypes()) {
    if (name == o.dds_name) return o;
  }
  throw std::runtime_error("no fastddsgen type " + name);
}

// A message of the plain type, freed with the type table.
struct Plain {
  explicit Plain(const msg::TypeEntry& e) : entry(e), p(e.create()) {}
  ~Plain() { entry.destroy(p); }
  const msg::TypeEntry& entry;
  void* p;
};

// A fastddsgen object, freed with its ops.
struct Vendor {
  explicit Vendor(const fastdds_gen::FastTypeOps& o) : ops(o), v(o.new_vendor()) {}
  ~Vendor() { ops.delete_vendor(v); }
  const fastdds_gen::FastTypeOps& ops;
  void* v;
};

std::unique_ptr<Payload> Serialize(TopicDataType& type, void* data) {
  auto payload = std::make_unique<Payload>(type.getSerializedSizeProvider(data)());
  EXPECT_TRUE(type.serialize(data, payload.get()));
  return payload;
}

TEST(FastddsPlainType, EveryTypeHasOneWithFastddsgensNameSizeAndKey) {
  ASSERT_EQ(fastdds_plain::AllPlainTypes().size(), msg::AllTypes().size());
  for (const auto& t : msg::AllTypes()) {
    SCOPED_TRACE(t.dds_name);
    const auto* entry = fastdds_plain::FindPlainType(t.dds_name);
    ASSERT_NE(entry, nullptr);
    std::unique_ptr<TopicDataType> ours(entry->make());
    std::unique_ptr<TopicDataType> gen(GeneratedOps(t.dds_name).make_pubsub_type());
    EXPECT_STREQ(ours->getName(), t.dds_name);
    EXPECT_STREQ(ours->getName(), gen->getName());
    EXPECT_EQ(ours->m_typeSize, gen->m_typeSize);
    EXPECT_FALSE(gen->m_isGetKeyDefined);  // no IDL type is keyed
    EXPECT_EQ(ours->m_isGetKeyDefined, gen->m_isGetKeyDefined);
  }
  EXPECT_EQ(fastdds_plain::FindPlainType("no_such::Type_"), nullptr);
}

// Serialises random messages with ours and with fastddsgen's (after the old
// conversion), requires identical bytes and the exact size estimate, and
// reads each one with the other side.
TEST(FastddsPlainType, BytesIdenticalToFastddsgenBothWays) {
  int compared = 0;
  for (const auto& t : msg::AllTypes()) {
    SCOPED_TRACE(t.dds_name);
    std::unique_ptr<TopicDataType> ours(fastdds_plain::FindPlainType(t.dds_name)->make());
    const auto& ops = GeneratedOps(t.dds_name);
    std::unique_ptr<TopicDataType> gen(ops.make_pubsub_type());
    for (int seed = 1; seed <= kSamplesPerType; ++seed) {
      Plain in(t);
      t.randomize(in.p, static_cast<uint64_t>(seed));
      auto a = Serialize(*ours, in.p);
      EXPECT_EQ(a->length, ours->getSerializedSizeProvider(in.p)());
      Vendor v(ops);
      ops.to_vendor(in.p, v.v);
      auto b = Serialize(*gen, v.v);
      ASSERT_EQ(a->length, b->length) << "seed " << seed;
      ASSERT_EQ(std::memcmp(a->data, b->data, a->length), 0) << "seed " << seed;

      Plain from_gen(t);
      ASSERT_TRUE(ours->deserialize(b.get(), from_gen.p));
      EXPECT_EQ(t.first_difference(in.p, from_gen.p), std::nullopt);
      Vendor v2(ops);
      ASSERT_TRUE(gen->deserialize(a.get(), v2.v));
      Plain from_ours(t);
      ops.from_vendor(v2.v, from_ours.p);
      EXPECT_EQ(t.first_difference(in.p, from_ours.p), std::nullopt);
      ++compared;
    }
  }
  EXPECT_EQ(compared, kSamplesPerType * static_cast<int>(msg::AllTypes().size()));
}

// A big-endian peer: both readers decode the same message.
TEST(FastddsPlainType, ReadsBigEndianSamples) {
  const msg::TypeEntry* t = msg::FindType("HumanPrediction");
  ASSERT_NE(t, nullptr);
  Plain in(*t);
  t->randomize(in.p, 7);
  std::unique_ptr<TopicDataType> ours(fastdds_plain::FindPlainType(t->dds_name)->make());
  Payload be(ours->getSerializedSizeProvider(in.p)());
  {
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(be.data), be.max_size);
    Cdr cdr(buffer, Cdr::BIG_ENDIANNESS, Cdr::DDS_CDR);
    cdr.serialize_encapsulation();
    fastdds_cdr::Write(cdr, *static_cast<const msg::HumanPrediction*>(in.p));
    be.length = static_cast<uint32_t>(cdr.getSerializedDataLength());
  }
  EXPECT_EQ(be.data[1], 0x00);  // CDR_BE
  Plain out(*t);
  ASSERT_TRUE(ours->deserialize(&be, out.p));
  EXPECT_EQ(t->first_difference(in.p, out.p), std::nullopt);
  const auto& ops = GeneratedOps(t->dds_name);
  std::unique_ptr<TopicDataType> gen(ops.make_pubsub_type());
  Vendor v(ops);
  ASSERT_TRUE(gen->deserialize(&be, v.v));
  Plain via_gen(*t);
  ops.from_vendor(v.v, via_gen.p);
  EXPECT_EQ(t->first_difference(in.p, via_gen.p), std::nullopt);
}

msg::HumanSkeleton Skeleton() {
  msg::HumanSkeleton s;
  s.header.frame_id = "world";
  s.joints.resize(3);
  for (auto& j : s.joints) j.name = "hand_r";
  return s;
}

// Every truncation of a sample is rejected and counted, and flags the thread.
TEST(FastddsPlainType, RejectsTruncatedSamples) {
  fastdds_plain::PlainTopicDataType<msg::HumanSkeleton> type;
  msg::HumanSkeleton s = Skeleton();
  auto full = Serialize(type, &s);
  for (uint32_t len = 0; len < full->length; ++len) {
    SCOPED_TRACE(len);
    const uint32_t saved = full->length;
    full->length = len;
    msg::HumanSkeleton out;
    fastdds_plain::ClearDeserializeFailure();
    EXPECT_FALSE(type.deserialize(full.get(), &out));
    EXPECT_TRUE(fastdds_plain::DeserializeFailed());
    full->length = saved;
  }
  EXPECT_EQ(type.rejected(), full->length);
  msg::HumanSkeleton out;
  fastdds_plain::ClearDeserializeFailure();
  EXPECT_TRUE(type.deserialize(full.get(), &out));
  EXPECT_FALSE(fastdds_plain::DeserializeFailed());
  EXPECT_EQ(msg::FirstDifference(s, out), std::nullopt);
}

// A sequence length far beyond the sample is refused before any allocation.
TEST(FastddsPlainType, RejectsSequenceLengthsTheSampleCannotHold) {
  fastdds_plain::PlainTopicDataType<msg::HumanSkeleton> type;
  msg::HumanSkeleton s = Skeleton();
  auto payload = Serialize(type, &s);
  std::size_t pos = fastdds_cdr::SizeAt(s.body_id, fastdds_cdr::SizeAt(s.header, 0));
  pos += Cdr::alignment(pos, 4);
  const std::size_t at = 4 + pos;  // after the encapsulation header
  uint32_t n = 0;
  std::memcpy(&n, payload->data + at, 4);
  ASSERT_EQ(n, 3u);  // little-endian host, as every machine we run on
  for (uint32_t bad : {4u, 1000u, 0x7fffffffu, 0xffffffffu}) {
    std::memcpy(payload->data + at, &bad, 4);
    msg::HumanSkeleton out;
    EXPECT_FALSE(type.deserialize(payload.get(), &out)) << bad;
  }
  EXPECT_EQ(type.rejected(), 4u);
}

// Random corruption (seeded): never a crash, every failure counted.
TEST(FastddsPlainType, SurvivesRandomCorruption) {
  const msg::TypeEntry* t = msg::FindType("HumanPrediction");
  std::unique_ptr<TopicDataType> ours(fastdds_plain::FindPlainType(t->dds_name)->make());
  Plain in(*t);
  t->randomize(in.p, 3);
  auto good = Serialize(*ours, in.p);
  std::mt19937 rng(42);
  std::uniform_int_distribution<uint32_t> word(0, good->length / 4 - 1);
  int rejected = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Payload bad(good->length);
    std::memcpy(bad.data, good->data, good->length);
    bad.length = good->length;
    const uint32_t w = 1 + word(rng) % (good->length / 4 - 1);  // keep the header
    const uint32_t value = rng();
    std::memcpy(bad.data + 4 * w, &value, 4);
    Plain out(*t);
    if (!ours->deserialize(&bad, out.p)) ++rejected;
  }
  EXPECT_GT(rejected, 0);
  EXPECT_EQ(static_cast<fastdds_plain::PlainTypeBase*>(ours.get())->rejected(), static_cast<uint64_t>(rejected));
}

}  // namespace
}  // namespace iplan::dds
