// dds_probe: a small DDS program for multi-process tests.
//
//   dds_probe roundtrip-pub --dds V --domain D --seed S --samples N
//       one writer per message type on rt/iplan/test/<Type>; writes N seeded
//       random samples of each once a reader matched, waits for acks.
//   dds_probe roundtrip-sub --dds V --domain D --seed S --samples N
//       receives them and compares field by field with the same seeded
//       samples; prints "OK <Type>" / "MISMATCH <Type>: <field>"; exit 0 when
//       every type arrived complete and equal.
//   dds_probe stream --dds V --domain D --rate HZ --publish-for S --mode M
//       publishes skeletons on the catalogue topic; after --publish-for
//       seconds it stops publishing but stays alive (deadline tests).
//       Modes: good, nan, backwards, wrong-size (malformed on purpose).
//       --ros2-default-qos: the writer offers what a ROS 2 default publisher
//       does (reliable, volatile, keep last 10, no deadline, infinite lease).
#include <signal.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <thread>

#include <CLI/CLI.hpp>

#include "iplan/dds/participant.h"
#include "iplan/framework/topics.h"
#include "iplan/msg/time.h"
#include "iplan/msg/type_table.h"

using namespace iplan;
using namespace std::chrono_literals;

namespace {

volatile sig_atomic_t g_stop = 0;

dds::QosProfile TestQos(int samples) {
  dds::QosProfile q = dds::QosProfile::LatchedState(std::chrono::nanoseconds(0), std::chrono::nanoseconds(0));
  q.depth = samples;
  return q;
}

uint64_t SampleSeed(uint64_t seed, std::size_t type_index, int i) {
  return seed * 1000003ULL + type_index * 1009ULL + static_cast<uint64_t>(i);
}

std::string TopicFor(const msg::TypeEntry& e) { return std::string("rt/iplan/test/") + e.cpp_name; }

int RoundtripPub(dds::Participant& p, uint64_t seed, int samples, double timeout_s) {
  const auto& types = msg::AllTypes();
  std::vector<std::unique_ptr<dds::AnyWriter>> writers;
  for (const auto& e : types) writers.push_back(std::make_unique<dds::AnyWriter>(p, TopicFor(e), e.dds_name, TestQos(samples)));
  const auto timeout = std::chrono::nanoseconds(static_cast<int64_t>(timeout_s * 1e9));
  for (auto& w : writers) {
    if (!w->WaitForReaders(1, timeout)) {
      std::cerr << "no reader matched " << w->topic() << "\n";
      return 1;
    }
  }
  for (std::size_t t = 0; t < types.size(); ++t) {
    void* m = types[t].create();
    for (int i = 0; i < samples; ++i) {
      types[t].randomize(m, SampleSeed(seed, t, i));
      std::string err;
      if (!writers[t]->WriteAny(m, &err)) {
        std::cerr << "write failed on " << writers[t]->topic() << ": " << err << "\n";
        return 1;
      }
    }
    types[t].destroy(m);
  }
  for (auto& w : writers) w->WaitForAcknowledgments(timeout);
  std::cout << "published " << samples << " samples of " << types.size() << " types" << std::endl;
  // Stay until the reader is done (it may still be receiving resends).
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!g_stop && std::chrono::steady_clock::now() < end) {
    bool any = false;
    for (auto& w : writers) any = any || w->MatchedReaders() > 0;
    if (!any) break;
    std::this_thread::sleep_for(20ms);
  }
  return 0;
}

int RoundtripSub(dds::Participant& p, uint64_t seed, int samples, double timeout_s) {
  const auto& types = msg::AllTypes();
  std::vector<std::unique_ptr<dds::AnyReader>> readers;
  std::map<const dds::AnyReader*, std::size_t> index;
  for (std::size_t t = 0; t < types.size(); ++t) {
    readers.push_back(std::make_unique<dds::AnyReader>(p, TopicFor(types[t]), types[t].dds_name, TestQos(samples)));
    index[readers.back().get()] = t;
  }
  std::cout << "ready" << std::endl;
  std::vector<int> received(types.size(), 0);
  std::vector<std::string> mismatch(types.size());
  std::size_t complete = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::nanoseconds(static_cast<int64_t>(timeout_s * 1e9));
  std::vector<dds::AnyReader*> ready;
  while (complete < types.size() && std::chrono::steady_clock::now() < end && !g_stop) {
    p.Wait(100ms, &ready);
    for (dds::AnyReader* r : ready) {
      const std::size_t t = index.at(r);
      r->TakeEvents();
      void* got = types[t].create();
      void* want = types[t].create();
      dds::SampleInfo info;
      while (r->TakeAny(got, &info)) {
        const int i = received[t]++;
        if (i >= samples) {
          mismatch[t] = "more samples than written";
          continue;
        }
        types[t].randomize(want, SampleSeed(seed, t, i));
        if (auto d = types[t].first_difference(want, got); d && mismatch[t].empty()) {
          mismatch[t] = "sample " + std::to_string(i) + ": " + *d;
        }
        if (received[t] == samples) ++complete;
      }
      types[t].destroy(got);
      types[t].destroy(want);
    }
  }
  int bad = 0;
  for (std::size_t t = 0; t < types.size(); ++t) {
    if (!mismatch[t].empty()) {
      std::cout << "MISMATCH " << types[t].cpp_name << ": " << mismatch[t] << "\n";
      ++bad;
    } else if (received[t] != samples) {
      std::cout << "MISSING " << types[t].cpp_name << ": " << received[t] << " of " << samples << "\n";
      ++bad;
    } else {
      std::cout << "OK " << types[t].cpp_name << " " << received[t] << "\n";
    }
  }
  std::cout << (bad == 0 ? "ALL OK" : "FAILED") << std::endl;
  return bad == 0 ? 0 : 1;
}

msg::HumanSkeleton MakeSkeleton(int k) {
  msg::HumanSkeleton s;
  s.header.stamp = msg::Now();
  s.header.frame_id = "world";
  s.body_id = 1;
  s.confidence = 1.0;
  const char* names[] = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l", "shoulder_r", "elbow_r", "hand_r"};
  for (int j = 0; j < 9; ++j) {
    msg::HumanJoint joint;
    joint.name = names[j];
    joint.position.x = 0.8 + 0.01 * j;
    joint.position.y = 0.1 * std::sin(0.1 * k + j);
    joint.position.z = 1.0 + 0.05 * j;
    joint.covariance = {1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4};
    joint.confidence = 1.0;
    s.joints.push_back(joint);
  }
  return s;
}

int Stream(dds::Participant& p, double rate, double publish_for, double duration, const std::string& mode,
           bool ros2_default_qos) {
  auto topic = framework::topics::HumanSkeleton();
  if (ros2_default_qos) {
    topic.qos.writer_reliability = dds::QosProfile::Reliability::kReliable;
    topic.qos.durability = dds::QosProfile::Durability::kVolatile;
    topic.qos.depth = 10;
    topic.qos.deadline = std::chrono::nanoseconds(0);
    topic.qos.liveliness_lease = std::chrono::nanoseconds(0);
  }
  dds::Writer<msg::HumanSkeleton> w(p, topic.name, topic.qos);
  w.WaitForReaders(1, 10s);
  std::cout << "publishing" << std::endl;
  const auto start = std::chrono::steady_clock::now();
  const auto period = std::chrono::nanoseconds(static_cast<int64_t>(1e9 / rate));
  auto next = start;
  int k = 0;
  bool announced_pause = false;
  while (!g_stop) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (duration > 0 && t >= duration) break;
    if (t < publish_for) {
      msg::HumanSkeleton s = MakeSkeleton(k);
      if (mode == "nan") {
        s.joints[5].position.x = std::numeric_limits<double>::quiet_NaN();
      } else if (mode == "backwards") {
        // Every other message is stamped 1 s in the past.
        if (k % 2 == 1) s.header.stamp = msg::TimeFromSeconds(msg::ToSeconds(s.header.stamp) - 1.0);
      } else if (mode == "wrong-size") {
        s.joints.clear();
      }
      w.Write(s);
      ++k;
    } else if (!announced_pause) {
      std::cout << "paused after " << k << std::endl;
      announced_pause = true;
    }
    next += period;
    std::this_thread::sleep_until(next);
  }
  std::cout << "published " << k << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dds_probe: DDS test program (see the header comment of dds_probe.cc)"};
  app.require_subcommand(1);
  std::string vendor = "cyclonedds";
  int domain = 0;
  uint64_t seed = 1;
  int samples = 3;
  double timeout = 30, rate = 30, publish_for = 1e9, duration = 0;
  std::string mode = "good";
  auto common = [&](CLI::App* sub) {
    sub->add_option("--dds", vendor);
    sub->add_option("--domain", domain);
    sub->add_option("--timeout", timeout);
  };
  auto* pub = app.add_subcommand("roundtrip-pub");
  auto* sub = app.add_subcommand("roundtrip-sub");
  auto* stream = app.add_subcommand("stream");
  for (auto* s : {pub, sub}) {
    common(s);
    s->add_option("--seed", seed);
    s->add_option("--samples", samples);
  }
  common(stream);
  stream->add_option("--rate", rate);
  stream->add_option("--publish-for", publish_for);
  stream->add_option("--duration", duration);
  stream->add_option("--mode", mode)->check(CLI::IsMember({"good", "nan", "backwards", "wrong-size"}));
  bool ros2_default_qos = false;
  stream->add_flag("--ros2-default-qos", ros2_default_qos);
  CLI11_PARSE(app, argc, argv);
  signal(SIGINT, [](int) { g_stop = 1; });
  signal(SIGTERM, [](int) { g_stop = 1; });
  try {
    dds::ParticipantOptions o;
    o.vendor = dds::ParseVendor(vendor);
    o.domain_id = domain;
    o.name = "dds_probe";
    auto p = dds::Participant::Create(o);
    if (*pub) return RoundtripPub(*p, seed, samples, timeout);
    if (*sub) return RoundtripSub(*p, seed, samples, timeout);
    return Stream(*p, rate, publish_for, duration, mode, ros2_default_qos);
  } catch (const std::exception& e) {
    std::cerr << "dds_probe: " << e.what() << "\n";
    return 2;
  }
}
