// fastdds_serialize_bench: the CPU cost of one Fast DDS hop's type support,
// without the network: what the writer does (size, serialise) and what the
// reader does (deserialise), for the skeleton and the prediction, with
//   plain    the data path: fastdds_plain_type.h on the iplan::msg type;
//   gen      the previous path: conversion to the fastddsgen class and its
//            PubSubType (and back on the reader side).
// Both produce the same bytes (fastdds_plain_type_test).
//
//   fastdds_serialize_bench [--benchmark_repetitions=N ...]  (Google Benchmark)
#include <memory>
#include <string>

#include <benchmark/benchmark.h>

#include "bench_messages.h"
#include "fastdds_convert.h"
#include "fastdds_plain_type.h"

namespace {

namespace msg = iplan::msg;
namespace idds = iplan::dds;
using Payload = eprosima::fastrtps::rtps::SerializedPayload_t;
using eprosima::fastdds::dds::TopicDataType;

const idds::fastdds_gen::FastTypeOps& GeneratedOps(const char* name) {
  for (const auto& o : idds::fastdds_gen::AllFastTypes()) {
    if (std::string(name) == o.dds_name) return o;
  }
  throw std::runtime_error(std::string("no fastddsgen type ") + name);
}

template <class T>
T Message();
template <>
msg::HumanSkeleton Message() { return iplan::bench::MakeSkeleton(); }
template <>
msg::HumanPrediction Message() { return iplan::bench::MakePrediction(); }

// The sample a writer would send, and a payload big enough for it.
template <class T>
struct Fixture {
  Fixture() : m(Message<T>()), ops(GeneratedOps(msg::TypeName<T>::kDds)), vendor(ops.new_vendor()) {
    ops.to_vendor(&m, vendor);
    payload = std::make_unique<Payload>(plain.getSerializedSizeProvider(&m)());
    if (!plain.serialize(&m, payload.get())) throw std::runtime_error("serialize failed");
  }
  ~Fixture() { ops.delete_vendor(vendor); }
  T m;
  iplan::dds::fastdds_plain::PlainTopicDataType<T> plain;
  const idds::fastdds_gen::FastTypeOps& ops;
  std::unique_ptr<TopicDataType> gen{ops.make_pubsub_type()};
  void* vendor;
  std::unique_ptr<Payload> payload;
};

template <class T>
void BM_WritePlain(benchmark::State& state) {
  Fixture<T> f;
  Payload out(f.payload->max_size);
  for (auto _ : state) {
    const uint32_t size = f.plain.getSerializedSizeProvider(&f.m)();
    benchmark::DoNotOptimize(size);
    f.plain.serialize(&f.m, &out);
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * f.payload->length);
}

template <class T>
void BM_WriteGen(benchmark::State& state) {
  Fixture<T> f;
  Payload out(f.payload->max_size);
  void* sample = f.ops.new_vendor();
  for (auto _ : state) {
    f.ops.to_vendor(&f.m, sample);  // what the backend did before each write
    const uint32_t size = f.gen->getSerializedSizeProvider(sample)();
    benchmark::DoNotOptimize(size);
    f.gen->serialize(sample, &out);
    benchmark::ClobberMemory();
  }
  f.ops.delete_vendor(sample);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * f.payload->length);
}

template <class T>
void BM_ReadPlain(benchmark::State& state) {
  Fixture<T> f;
  T into;  // reused, as the framework's subscription does
  for (auto _ : state) {
    f.plain.deserialize(f.payload.get(), &into);
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * f.payload->length);
}

template <class T>
void BM_ReadGen(benchmark::State& state) {
  Fixture<T> f;
  void* sample = f.ops.new_vendor();
  T into;
  for (auto _ : state) {
    f.gen->deserialize(f.payload.get(), sample);
    f.ops.from_vendor(sample, &into);  // what the backend did after each take
    benchmark::ClobberMemory();
  }
  f.ops.delete_vendor(sample);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * f.payload->length);
}

BENCHMARK_TEMPLATE(BM_WritePlain, msg::HumanSkeleton)->Name("skeleton/write/plain");
BENCHMARK_TEMPLATE(BM_WriteGen, msg::HumanSkeleton)->Name("skeleton/write/gen");
BENCHMARK_TEMPLATE(BM_ReadPlain, msg::HumanSkeleton)->Name("skeleton/read/plain");
BENCHMARK_TEMPLATE(BM_ReadGen, msg::HumanSkeleton)->Name("skeleton/read/gen");
BENCHMARK_TEMPLATE(BM_WritePlain, msg::HumanPrediction)->Name("prediction/write/plain");
BENCHMARK_TEMPLATE(BM_WriteGen, msg::HumanPrediction)->Name("prediction/write/gen");
BENCHMARK_TEMPLATE(BM_ReadPlain, msg::HumanPrediction)->Name("prediction/read/plain");
BENCHMARK_TEMPLATE(BM_ReadGen, msg::HumanPrediction)->Name("prediction/read/gen");

}  // namespace

BENCHMARK_MAIN();
