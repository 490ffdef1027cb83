// dds_latency_bench: what the iplan DDS framework costs over the bare vendor
// API, for a skeleton message and a 10-action prediction message, on both
// vendors, in one run.
//
// Latency: ping-pong between two processes over loopback (same host, same
// shipped loopback transport config); one-way = round trip / 2.
//   raw        vendor-generated types, vendor API, a wait set; the echo side
//              writes back the sample it took.
//   framework  iplan::msg types through idds::Writer/Reader (Fast DDS: the
//              plain types serialised directly; Cyclone: conversion to and
//              from idlc's structs), and on both sides a framework::Node whose
//              subscription runs the boundary check before the callback.
// Throughput: the sender writes as fast as the writer accepts for a fixed
// time (reliable, keep last 100); the receiver counts what it delivers.
//
// Raw and framework runs of a case alternate (raw 1, framework 1, raw 2, ...)
// so that a change of the shared machine's speed between runs hits both; the
// framework line also gives its overhead per pair of runs.
//
//   dds_latency_bench [--iterations N] [--runs R] [--json FILE]
//                     [--vendor V] [--msg M] [--impl I] [--lease-ms L]
// (--vendor/--msg/--impl select cases; --lease-ms gives the framework's
// topics a liveliness lease, as the services' topics have; the echo/sink
// roles are the same binary started as child processes).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

#include <CLI/CLI.hpp>
#include <dds/dds.h>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "bench_messages.h"
#include "cyclone_convert.h"
#include "fastdds_convert.h"
#include "iplan/core/process.h"
#include "iplan/core/stats.h"
#include "iplan/dds/participant.h"
#include "iplan/framework/node.h"
#include "iplan/msg/time.h"

namespace msg = iplan::msg;
namespace framework = iplan::framework;
namespace core = iplan::core;
namespace idds = iplan::dds;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;
namespace fdds = eprosima::fastdds::dds;

namespace {

const std::string kConfigDir = IPLAN_SOURCE_DIR "/config/dds";

// Liveliness lease of the framework's topics, ms (--lease-ms); 0: infinite.
// A finite lease is what the services' topics have: on Fast DDS each
// framework reader then has a liveliness watch reader besides (docs/dds.md).
int g_lease_ms = 0;

idds::QosProfile BenchQos(int depth) {
  idds::QosProfile q = idds::QosProfile::Command(std::chrono::milliseconds(g_lease_ms));
  q.depth = depth;
  return q;
}

// ---------------------------------------------------------------- raw Fast DDS
struct RawFast {
  fdds::DomainParticipant* participant = nullptr;
  fdds::Publisher* pub = nullptr;
  fdds::Subscriber* sub = nullptr;
  fdds::DataWriter* writer = nullptr;
  fdds::DataReader* reader = nullptr;
  fdds::WaitSet waitset;
  const idds::fastdds_gen::FastTypeOps* ops = nullptr;
  void* sample = nullptr;

  RawFast(int domain, const std::string& type, const std::string& out_topic, const std::string& in_topic, int depth) {
    for (const auto& o : idds::fastdds_gen::AllFastTypes()) {
      if (type == o.dds_name) ops = &o;
    }
    auto* f = fdds::DomainParticipantFactory::get_instance();
    f->load_XML_profiles_file(kConfigDir + "/fastdds-loopback.xml");
    participant = f->create_participant_with_profile(domain, "iplan_participant");
    fdds::TypeSupport ts(ops->make_pubsub_type());
    ts.register_type(participant);
    auto* to = participant->create_topic(out_topic, type, fdds::TOPIC_QOS_DEFAULT);
    auto* ti = participant->create_topic(in_topic, type, fdds::TOPIC_QOS_DEFAULT);
    pub = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    sub = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    fdds::DataWriterQos wq = pub->get_default_datawriter_qos();
    wq.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
    wq.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    wq.history().depth = depth;
    wq.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 100000000);
    wq.data_sharing().off();
    wq.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    writer = pub->create_datawriter(to, wq);
    fdds::DataReaderQos rq = sub->get_default_datareader_qos();
    rq.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
    rq.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    rq.history().depth = depth;
    rq.data_sharing().off();
    rq.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    reader = sub->create_datareader(ti, rq);
    reader->get_statuscondition().set_enabled_statuses(fdds::StatusMask::data_available());
    waitset.attach_condition(reader->get_statuscondition());
    sample = ops->new_vendor();
  }
  ~RawFast() {
    waitset.detach_condition(reader->get_statuscondition());
    participant->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant);
    ops->delete_vendor(sample);
  }
  void Wait() {
    fdds::ConditionSeq active;
    waitset.wait(active, eprosima::fastrtps::Duration_t(1, 0));
  }
  bool Take() {
    fdds::SampleInfo info;
    return reader->take_next_sample(sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK &&
           info.valid_data;
  }
  void Write() { writer->write(sample); }
  bool Matched() {
    fdds::PublicationMatchedStatus s;
    writer->get_publication_matched_status(s);
    fdds::SubscriptionMatchedStatus r;
    reader->get_subscription_matched_status(r);
    return s.current_count > 0 && r.current_count > 0;
  }
};

// ---------------------------------------------------------------- raw Cyclone
struct RawCyclone {
  dds_entity_t participant, writer, reader, waitset;
  const idds::cyclone_gen::CycloneTypeOps* ops = nullptr;
  std::vector<std::max_align_t> own;
  idds::cyclone_gen::Arena arena;
  void* loaned[1] = {nullptr};
  dds_sample_info_t info;

  RawCyclone(int domain, const std::string& type, const std::string& out_topic, const std::string& in_topic, int depth) {
    for (const auto& o : idds::cyclone_gen::AllCycloneTypes()) {
      if (type == o.dds_name) ops = &o;
    }
    const std::string uri = "file://" + kConfigDir + "/cyclonedds-loopback.xml";
    dds_create_domain(static_cast<dds_domainid_t>(domain), uri.c_str());
    participant = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
    const dds_entity_t to = dds_create_topic(participant, ops->descriptor, out_topic.c_str(), nullptr, nullptr);
    const dds_entity_t ti = dds_create_topic(participant, ops->descriptor, in_topic.c_str(), nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
    dds_data_representation_id_t x1 = DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(q, 1, &x1);
    writer = dds_create_writer(participant, to, q, nullptr);
    reader = dds_create_reader(participant, ti, q, nullptr);
    dds_delete_qos(q);
    dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
    waitset = dds_create_waitset(participant);
    dds_waitset_attach(waitset, reader, 1);
    own.resize(ops->vendor_size / sizeof(std::max_align_t) + 1);
  }
  ~RawCyclone() { dds_delete(participant); }
  void Fill(const void* plain) { ops->to_vendor(plain, own.data(), arena); }
  void Wait() {
    dds_attach_t xs[1];
    dds_waitset_wait(waitset, xs, 1, DDS_SECS(1));
  }
  bool Take() {
    uint32_t st;
    dds_take_status(reader, &st, DDS_DATA_AVAILABLE_STATUS);
    loaned[0] = nullptr;
    const dds_return_t n = dds_take(reader, loaned, &info, 1, 1);
    if (n <= 0) return false;
    if (!info.valid_data) {
      dds_return_loan(reader, loaned, n);
      return false;
    }
    return true;
  }
  void WriteLoanedBackAndReturn() {
    dds_write(writer, loaned[0]);
    dds_return_loan(reader, loaned, 1);
  }
  void ReturnLoan() { dds_return_loan(reader, loaned, 1); }
  void WriteOwn() { dds_write(writer, own.data()); }
  bool Matched() {
    dds_publication_matched_status_t s;
    dds_get_publication_matched_status(writer, &s);
    dds_subscription_matched_status_t r;
    dds_get_subscription_matched_status(reader, &r);
    return s.current_count > 0 && r.current_count > 0;
  }
};

struct Case {
  std::string impl;    // raw | framework
  std::string vendor;  // fastdds | cyclonedds
  std::string msg;     // skeleton | prediction
};

std::string TypeOf(const std::string& m) {
  return m == "skeleton" ? msg::TypeName<msg::HumanSkeleton>::kDds : msg::TypeName<msg::HumanPrediction>::kDds;
}

// A framework node on a participant of its own, without diagnostics.
struct BenchNode {
  std::unique_ptr<idds::Participant> participant;
  std::unique_ptr<framework::Node> node;
};

BenchNode MakeBenchNode(idds::Vendor vendor, int domain, const std::string& name) {
  idds::ParticipantOptions o;
  o.vendor = vendor;
  o.domain_id = domain;
  BenchNode b;
  b.participant = idds::Participant::Create(o);
  framework::NodeOptions no;
  no.diagnostics_period = 0;
  b.node = std::make_unique<framework::Node>(name, *b.participant, no);
  return b;
}

// ------------------------------------------------------------------ echo role
template <class T>
int FrameworkEcho(idds::Vendor vendor, int domain, double seconds) {
  BenchNode bench = MakeBenchNode(vendor, domain, "echo");
  framework::Node& node = *bench.node;
  auto& w = node.Advertise(framework::Topic<T>{"rt/bench/pong", BenchQos(5)});
  node.Subscribe(framework::Topic<T>{"rt/bench/ping", BenchQos(5)},
                 std::function<void(const T&, const idds::SampleInfo&)>([&](const T& m, const idds::SampleInfo&) { w.Write(m); }),
                 framework::SubscribeOptions{false});
  std::cout << "ready" << std::endl;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) node.SpinOnce(100ms);
  return 0;
}

int Echo(const Case& c, int domain, double seconds) {
  spdlog::set_level(spdlog::level::warn);
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  if (c.impl == "framework") {
    const auto v = idds::ParseVendor(c.vendor);
    return c.msg == "skeleton" ? FrameworkEcho<msg::HumanSkeleton>(v, domain, seconds)
                               : FrameworkEcho<msg::HumanPrediction>(v, domain, seconds);
  }
  if (c.vendor == "fastdds") {
    RawFast r(domain, TypeOf(c.msg), "rt/bench/pong", "rt/bench/ping", 5);
    std::cout << "ready" << std::endl;
    while (Clock::now() < end) {
      r.Wait();
      while (r.Take()) r.Write();
    }
  } else {
    RawCyclone r(domain, TypeOf(c.msg), "rt/bench/pong", "rt/bench/ping", 5);
    std::cout << "ready" << std::endl;
    while (Clock::now() < end) {
      r.Wait();
      while (r.Take()) r.WriteLoanedBackAndReturn();
    }
  }
  return 0;
}

// ------------------------------------------------------------------ ping role
// Returns one-way latencies in microseconds.
template <class T>
std::vector<double> FrameworkPing(idds::Vendor vendor, int domain, const T& m, int warmup, int n) {
  BenchNode bench = MakeBenchNode(vendor, domain, "ping");
  framework::Node& node = *bench.node;
  auto& w = node.Advertise(framework::Topic<T>{"rt/bench/ping", BenchQos(5)});
  int got = 0;
  node.Subscribe(framework::Topic<T>{"rt/bench/pong", BenchQos(5)},
                 std::function<void(const T&, const idds::SampleInfo&)>([&](const T&, const idds::SampleInfo&) { ++got; }),
                 framework::SubscribeOptions{false});
  // Matched both ways: send until an echo comes back.
  const auto deadline = Clock::now() + 20s;
  while (got == 0 && Clock::now() < deadline) {
    w.Write(m);
    node.SpinOnce(50ms);
  }
  std::vector<double> us;
  for (int i = 0; i < warmup + n; ++i) {
    got = 0;
    const auto t0 = Clock::now();
    w.Write(m);
    while (got == 0) node.SpinOnce(1s);
    const double rtt = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    if (i >= warmup) us.push_back(rtt / 2);
  }
  return us;
}

std::vector<double> Ping(const Case& c, int domain, int warmup, int n) {
  const auto skeleton = iplan::bench::MakeSkeleton();
  const auto prediction = iplan::bench::MakePrediction();
  if (c.impl == "framework") {
    const auto v = idds::ParseVendor(c.vendor);
    return c.msg == "skeleton" ? FrameworkPing(v, domain, skeleton, warmup, n)
                               : FrameworkPing(v, domain, prediction, warmup, n);
  }
  const void* plain = c.msg == "skeleton" ? static_cast<const void*>(&skeleton) : static_cast<const void*>(&prediction);
  std::vector<double> us;
  auto loop = [&](auto& r, auto write, auto take) {
    const auto deadline = Clock::now() + 20s;
    bool echoed = false;
    while (!echoed && Clock::now() < deadline) {
      write();
      r.Wait();
      while (take()) echoed = true;
    }
    for (int i = 0; i < warmup + n; ++i) {
      const auto t0 = Clock::now();
      write();
      bool got = false;
      while (!got) {
        r.Wait();
        while (take()) got = true;
      }
      const double rtt = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
      if (i >= warmup) us.push_back(rtt / 2);
    }
  };
  if (c.vendor == "fastdds") {
    RawFast r(domain, TypeOf(c.msg), "rt/bench/ping", "rt/bench/pong", 5);
    r.ops->to_vendor(plain, r.sample);
    auto* out = r.ops->new_vendor();
    r.ops->to_vendor(plain, out);
    loop(r, [&] { r.writer->write(out); }, [&] { return r.Take(); });
    r.ops->delete_vendor(out);
  } else {
    RawCyclone r(domain, TypeOf(c.msg), "rt/bench/ping", "rt/bench/pong", 5);
    r.Fill(plain);
    loop(r, [&] { r.WriteOwn(); }, [&] {
      if (!r.Take()) return false;
      r.ReturnLoan();
      return true;
    });
  }
  return us;
}

// ------------------------------------------------------------ throughput role
// Sink: counts delivered messages; prints "rate <msgs/s> <count>" at the end.
int Sink(const Case& c, int domain, double seconds) {
  spdlog::set_level(spdlog::level::warn);
  uint64_t count = 0;
  Clock::time_point first{}, last{};
  auto on = [&] {
    if (count++ == 0) first = Clock::now();
    last = Clock::now();
  };
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  if (c.impl == "framework") {
    idds::ParticipantOptions o;
    o.vendor = idds::ParseVendor(c.vendor);
    o.domain_id = domain;
    auto p = idds::Participant::Create(o);
    framework::NodeOptions no;
    no.diagnostics_period = 0;
    framework::Node node("sink", *p, no);
    if (c.msg == "skeleton") {
      node.Subscribe(framework::Topic<msg::HumanSkeleton>{"rt/bench/ping", BenchQos(100)},
                     std::function<void(const msg::HumanSkeleton&, const idds::SampleInfo&)>(
                         [&](const msg::HumanSkeleton&, const idds::SampleInfo&) { on(); }),
                     framework::SubscribeOptions{false});
    } else {
      node.Subscribe(framework::Topic<msg::HumanPrediction>{"rt/bench/ping", BenchQos(100)},
                     std::function<void(const msg::HumanPrediction&, const idds::SampleInfo&)>(
                         [&](const msg::HumanPrediction&, const idds::SampleInfo&) { on(); }),
                     framework::SubscribeOptions{false});
    }
    std::cout << "ready" << std::endl;
    while (Clock::now() < end) node.SpinOnce(100ms);
  } else if (c.vendor == "fastdds") {
    RawFast r(domain, TypeOf(c.msg), "rt/bench/unused", "rt/bench/ping", 100);
    std::cout << "ready" << std::endl;
    while (Clock::now() < end) {
      r.Wait();
      while (r.Take()) on();
    }
  } else {
    RawCyclone r(domain, TypeOf(c.msg), "rt/bench/unused", "rt/bench/ping", 100);
    std::cout << "ready" << std::endl;
    while (Clock::now() < end) {
      r.Wait();
      while (r.Take()) {
        r.ReturnLoan();
        on();
      }
    }
  }
  const double dt = std::chrono::duration<double>(last - first).count();
  std::cout << "rate " << (count > 1 && dt > 0 ? (count - 1) / dt : 0.0) << " " << count << std::endl;
  return 0;
}

// Source: writes for `seconds`; returns messages written.
uint64_t Source(const Case& c, int domain, double seconds) {
  const auto skeleton = iplan::bench::MakeSkeleton();
  const auto prediction = iplan::bench::MakePrediction();
  uint64_t n = 0;
  auto run = [&](auto write, auto matched) {
    const auto wait_end = Clock::now() + 20s;
    while (!matched() && Clock::now() < wait_end) std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(200ms);
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) {
      write();
      ++n;
    }
  };
  if (c.impl == "framework") {
    idds::ParticipantOptions o;
    o.vendor = idds::ParseVendor(c.vendor);
    o.domain_id = domain;
    auto p = idds::Participant::Create(o);
    if (c.msg == "skeleton") {
      idds::Writer<msg::HumanSkeleton> w(*p, "rt/bench/ping", BenchQos(100));
      run([&] { w.Write(skeleton); }, [&] { return w.MatchedReaders() > 0; });
      w.WaitForAcknowledgments(5s);
    } else {
      idds::Writer<msg::HumanPrediction> w(*p, "rt/bench/ping", BenchQos(100));
      run([&] { w.Write(prediction); }, [&] { return w.MatchedReaders() > 0; });
      w.WaitForAcknowledgments(5s);
    }
  } else {
    const void* plain = c.msg == "skeleton" ? static_cast<const void*>(&skeleton) : static_cast<const void*>(&prediction);
    if (c.vendor == "fastdds") {
      RawFast r(domain, TypeOf(c.msg), "rt/bench/ping", "rt/bench/unused", 100);
      r.ops->to_vendor(plain, r.sample);
      run([&] { r.Write(); }, [&] {
        fdds::PublicationMatchedStatus s;
        r.writer->get_publication_matched_status(s);
        return s.current_count > 0;
      });
      r.writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5, 0));
    } else {
      RawCyclone r(domain, TypeOf(c.msg), "rt/bench/ping", "rt/bench/unused", 100);
      r.Fill(plain);
      run([&] { r.WriteOwn(); }, [&] {
        dds_publication_matched_status_t s;
        dds_get_publication_matched_status(r.writer, &s);
        return s.current_count > 0;
      });
      dds_wait_for_acks(r.writer, DDS_SECS(5));
    }
  }
  return n;
}

// ------------------------------------------------------------------ driver
struct CaseRuns {
  std::vector<double> p50s, p99s, rates;  // one per run
};

// One run of case `c`: a ping-pong latency run on `latency_domain`, then a
// throughput run on `throughput_domain`.
void MeasureRun(const std::string& self, const Case& c, int latency_domain, int throughput_domain, int iterations,
                double throughput_seconds, CaseRuns* out) {
  {
    core::Process echo({self, "--role", "echo", "--impl", c.impl, "--vendor", c.vendor, "--msg", c.msg, "--domain",
                        std::to_string(latency_domain), "--seconds", "120", "--lease-ms", std::to_string(g_lease_ms)});
    echo.WaitForOutput("ready", 20s);
    const auto s = core::Summarize(Ping(c, latency_domain, 200, iterations));
    out->p50s.push_back(s.p50);
    out->p99s.push_back(s.p99);
  }
  core::Process sink({self, "--role", "sink", "--impl", c.impl, "--vendor", c.vendor, "--msg", c.msg, "--domain",
                      std::to_string(throughput_domain), "--seconds", std::to_string(throughput_seconds + 3),
                      "--lease-ms", std::to_string(g_lease_ms)});
  sink.WaitForOutput("ready", 20s);
  Source(c, throughput_domain, throughput_seconds);
  sink.Wait(30s);
  const std::string text = sink.Stdout();
  const auto pos = text.find("rate ");
  out->rates.push_back(pos == std::string::npos ? 0.0 : std::stod(text.substr(pos + 5)));
}

std::string MedianSpread(const std::vector<double>& v, int precision) {
  const auto s = core::Summarize(v);
  std::ostringstream o;
  o << std::fixed << std::setprecision(precision) << s.p50 << " [" << s.min << ", " << s.max << "]";
  return o.str();
}

// One line of the table; with `raw`, also what the framework adds to the raw
// p50: from the medians, and per pair of runs (run r of raw with run r of the
// framework).
void PrintCase(const std::string& m, const std::string& v, const std::string& i, const CaseRuns& cr,
               const CaseRuns* raw) {
  std::cout << std::left << std::setw(11) << m << std::setw(11) << v << std::setw(10) << i << std::setw(30)
            << MedianSpread(cr.p50s, 1) << std::setw(30) << MedianSpread(cr.p99s, 1) << std::fixed
            << std::setprecision(0) << core::Summarize(cr.rates).p50;
  if (raw && !raw->p50s.empty()) {
    const double raw_p50 = core::Summarize(raw->p50s).p50;
    std::vector<double> pairs;
    for (std::size_t r = 0; r < cr.p50s.size() && r < raw->p50s.size(); ++r) {
      pairs.push_back(100.0 * (cr.p50s[r] - raw->p50s[r]) / raw->p50s[r]);
    }
    std::cout << "   framework adds " << std::setprecision(1) << 100.0 * (core::Summarize(cr.p50s).p50 - raw_p50) / raw_p50
              << " % to the raw p50 (per run pair: " << MedianSpread(pairs, 1) << " %)";
  }
  std::cout << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dds_latency_bench: framework vs bare vendor latency and throughput"};
  std::string role = "driver", impl, vendor, message, json_file;
  int domain = 150, iterations = 2000, runs = 3;
  double seconds = 60, throughput_seconds = 2;
  app.add_option("--role", role)->check(CLI::IsMember({"driver", "echo", "sink"}));
  app.add_option("--impl", impl, "echo/sink: the side to run; driver: only this impl")
      ->check(CLI::IsMember({"raw", "framework"}));
  app.add_option("--vendor", vendor, "echo/sink: the vendor; driver: only this vendor")
      ->check(CLI::IsMember({"cyclonedds", "fastdds"}));
  app.add_option("--msg", message, "echo/sink: the message; driver: only this message")
      ->check(CLI::IsMember({"skeleton", "prediction"}));
  app.add_option("--domain", domain);
  app.add_option("--seconds", seconds);
  app.add_option("--iterations", iterations, "ping-pongs per run")->capture_default_str();
  app.add_option("--runs", runs, "runs per case (median and spread are over runs)")->capture_default_str();
  app.add_option("--throughput-seconds", throughput_seconds)->capture_default_str();
  app.add_option("--json", json_file, "also write the results as JSON");
  app.add_option("--lease-ms", g_lease_ms, "liveliness lease of the framework's topics, ms (0: infinite)")
      ->check(CLI::Range(0, 60000))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (role == "echo") return Echo({impl, vendor, message}, domain, seconds);
  if (role == "sink") return Sink({impl, vendor, message}, domain, seconds);

  spdlog::set_level(spdlog::level::warn);
  const std::string self = core::ExecutableDir() + "/dds_latency_bench";
  nlohmann::json results = nlohmann::json::array();
  std::cout << "one-way latency = round trip / 2 over loopback, " << iterations << " ping-pongs x " << runs
            << " runs; throughput over " << throughput_seconds << " s; framework lease "
            << (g_lease_ms > 0 ? std::to_string(g_lease_ms) + " ms" : std::string("infinite")) << "\n\n";
  std::cout << std::left << std::setw(11) << "message" << std::setw(11) << "vendor" << std::setw(10) << "impl"
            << std::setw(30) << "p50 us (median [min, max])" << std::setw(30) << "p99 us (median [min, max])"
            << "throughput msg/s (median)\n";
  int dom = domain;
  for (const std::string m : {"skeleton", "prediction"}) {
    if (!message.empty() && m != message) continue;
    for (const std::string v : {"cyclonedds", "fastdds"}) {
      if (!vendor.empty() && v != vendor) continue;
      std::vector<std::string> impls;
      for (const std::string i : {"raw", "framework"}) {
        if (impl.empty() || i == impl) impls.push_back(i);
      }
      // Raw and framework alternate run by run, so a change of the shared
      // machine's speed between runs hits both alike (paired runs).
      std::map<std::string, CaseRuns> by_impl;
      for (int r = 0; r < runs; ++r) {
        for (const std::string& i : impls) {
          const int latency_domain = dom++ % 200 + 1, throughput_domain = dom++ % 200 + 1;
          MeasureRun(self, {i, v, m}, latency_domain, throughput_domain, iterations, throughput_seconds, &by_impl[i]);
        }
      }
      for (const std::string& i : impls) {
        const CaseRuns& cr = by_impl[i];
        PrintCase(m, v, i, cr, i == "framework" && by_impl.count("raw") ? &by_impl["raw"] : nullptr);
        results.push_back({{"message", m}, {"vendor", v}, {"impl", i}, {"p50_us_runs", cr.p50s},
                           {"p99_us_runs", cr.p99s}, {"throughput_msgs_per_s_runs", cr.rates}});
      }
    }
  }
  if (!json_file.empty()) std::ofstream(json_file) << results.dump(2) << "\n";
  return 0;
}
