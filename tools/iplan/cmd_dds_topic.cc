// iplan topic list | echo | hz | pub: watch and drive any topic, on either
// DDS vendor.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <iomanip>
#include <iostream>
#include <map>
#include <thread>

#include "command_registry.h"
#include "dds_common.h"
#include "iplan/msg/json.h"
#include "iplan/msg/time.h"
#include "iplan/msg/type_table.h"

namespace iplan::cli {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

volatile sig_atomic_t g_stop = 0;
void InstallStop() {
  g_stop = 0;
  signal(SIGINT, [](int) { g_stop = 1; });
  signal(SIGTERM, [](int) { g_stop = 1; });
}

std::chrono::nanoseconds Seconds(double s) { return std::chrono::nanoseconds(static_cast<int64_t>(s * 1e9)); }

struct ListOptions {
  DdsOptions dds;
  double wait = 2.0;
  bool all = false;
};

int RunList(const ListOptions& o) {
  auto p = MakeParticipant(o.dds, "iplan-topic-list", true);
  std::this_thread::sleep_for(Seconds(o.wait));
  struct Row {
    std::string type;
    int writers = 0, readers = 0;
  };
  std::map<std::string, Row> rows;
  for (const auto& e : p->Endpoints()) {
    if (e.topic.rfind("DCPS", 0) == 0) continue;  // built-in topics
    Row& r = rows[e.topic];
    r.type = e.type;
    (e.is_writer ? r.writers : r.readers)++;
  }
  if (o.all) {
    for (const auto& t : framework::topics::All()) {
      if (!rows.count(t.name)) rows[t.name].type = t.type;
    }
  }
  if (rows.empty()) {
    std::cout << "no topics on domain " << p->domain_id() << " (" << dds::ToString(p->vendor())
              << ") after " << o.wait << " s\n";
    return 0;
  }
  std::size_t w = 5;
  for (const auto& [name, r] : rows) w = std::max(w, RosTopicName(name).size());
  std::cout << std::left << std::setw(static_cast<int>(w) + 2) << "TOPIC" << std::setw(9) << "WRITERS"
            << std::setw(9) << "READERS" << "TYPE\n";
  for (const auto& [name, r] : rows) {
    std::cout << std::left << std::setw(static_cast<int>(w) + 2) << RosTopicName(name) << std::setw(9) << r.writers
              << std::setw(9) << r.readers << r.type << "\n";
  }
  return 0;
}

// Finds the type of a topic: the catalogue, else discovery.
const msg::TypeEntry* ResolveType(const std::string& topic, const std::string& type_option, DdsOptions dds,
                                  dds::QosProfile* qos) {
  *qos = dds::QosProfile::Relaxed();
  if (!type_option.empty()) {
    const msg::TypeEntry* e = msg::FindType(type_option);
    if (!e) throw std::invalid_argument("unknown type '" + type_option + "'");
    if (auto t = FindCatalogueTopic(topic)) *qos = t->qos.RelaxedFor();
    return e;
  }
  if (auto t = FindCatalogueTopic(topic)) {
    *qos = t->qos.RelaxedFor();
    return msg::FindType(t->type);
  }
  auto p = MakeParticipant(dds, "iplan-topic-discover", true);
  const auto end = Clock::now() + 3s;
  while (Clock::now() < end) {
    for (const auto& e : p->Endpoints()) {
      if (e.topic == topic) {
        if (const msg::TypeEntry* t = msg::FindType(e.type)) return t;
        throw std::runtime_error("topic " + topic + " has type " + e.type + ", which iplan does not know");
      }
    }
    std::this_thread::sleep_for(50ms);
  }
  throw std::runtime_error("topic " + topic + " is not an iplan topic and nobody publishes it; give --type");
}

struct EchoOptions {
  DdsOptions dds;
  std::string topic, type;
  int count = 0;
  double timeout = 0;
  bool pretty = false;
};

int RunEcho(const EchoOptions& o) {
  const std::string topic = DdsTopicName(o.topic);
  dds::QosProfile qos;
  const msg::TypeEntry* type = ResolveType(topic, o.type, o.dds, &qos);
  auto p = MakeParticipant(o.dds, "iplan-topic-echo");
  dds::AnyReader reader(*p, topic, type->dds_name, qos);
  void* m = type->create();
  InstallStop();
  int n = 0;
  const auto end = o.timeout > 0 ? Clock::now() + Seconds(o.timeout) : Clock::time_point::max();
  std::vector<dds::AnyReader*> ready;
  dds::SampleInfo info;
  while (!g_stop && (o.count <= 0 || n < o.count) && Clock::now() < end) {
    p->Wait(100ms, &ready);
    reader.TakeEvents();
    while ((o.count <= 0 || n < o.count) && reader.TakeAny(m, &info)) {
      std::cout << type->to_json(m).dump(o.pretty ? 2 : -1) << std::endl;
      ++n;
    }
  }
  type->destroy(m);
  if (n == 0 && o.timeout > 0) {
    std::cerr << "iplan topic echo: no message on " << RosTopicName(topic) << " within " << o.timeout << " s\n";
    return 1;
  }
  return 0;
}

struct HzOptions {
  DdsOptions dds;
  std::string topic, type;
  int window = 100;
  double duration = 0;
};

int RunHz(const HzOptions& o) {
  const std::string topic = DdsTopicName(o.topic);
  dds::QosProfile qos;
  const msg::TypeEntry* type = ResolveType(topic, o.type, o.dds, &qos);
  auto p = MakeParticipant(o.dds, "iplan-topic-hz");
  dds::AnyReader reader(*p, topic, type->dds_name, qos);
  void* m = type->create();
  InstallStop();
  std::deque<double> times;
  const auto start = Clock::now();
  auto next_report = start + 1s;
  std::vector<dds::AnyReader*> ready;
  dds::SampleInfo info;
  uint64_t total = 0;
  while (!g_stop && (o.duration <= 0 || Clock::now() - start < Seconds(o.duration))) {
    p->Wait(50ms, &ready);
    reader.TakeEvents();
    while (reader.TakeAny(m, &info)) {
      times.push_back(std::chrono::duration<double>(Clock::now() - start).count());
      if (static_cast<int>(times.size()) > o.window + 1) times.pop_front();
      ++total;
    }
    if (Clock::now() >= next_report) {
      next_report += 1s;
      if (times.size() < 2) {
        std::cout << "no new messages" << std::endl;
        continue;
      }
      std::vector<double> dt;
      for (std::size_t i = 1; i < times.size(); ++i) dt.push_back(times[i] - times[i - 1]);
      double mean = 0;
      for (double d : dt) mean += d;
      mean /= dt.size();
      double var = 0;
      for (double d : dt) var += (d - mean) * (d - mean);
      const double sd = std::sqrt(var / dt.size());
      std::cout << std::fixed << std::setprecision(3) << "average rate: " << 1.0 / mean << " Hz\n"
                << "  min: " << *std::min_element(dt.begin(), dt.end()) << " s  max: "
                << *std::max_element(dt.begin(), dt.end()) << " s  std dev: " << std::setprecision(5) << sd
                << " s  window: " << dt.size() + 1 << std::endl;
    }
  }
  type->destroy(m);
  std::cout << "received " << total << " messages" << std::endl;
  return 0;
}

struct PubOptions {
  DdsOptions dds;
  std::string topic, type, json;
  double rate = 0;
  int count = 1;
  bool stamp_now = false;
  double wait_readers = 2.0;
};

int RunPub(const PubOptions& o) {
  const std::string topic = DdsTopicName(o.topic);
  const msg::TypeEntry* type = nullptr;
  dds::QosProfile qos = dds::QosProfile::Command(std::chrono::nanoseconds(0));
  if (!o.type.empty()) {
    type = msg::FindType(o.type);
    if (!type) throw std::invalid_argument("unknown type '" + o.type + "'");
  }
  if (auto t = FindCatalogueTopic(topic)) {
    if (!type) type = msg::FindType(t->type);
    qos = t->qos;
  }
  if (!type) throw std::invalid_argument("topic " + topic + " is not an iplan topic: give --type");
  void* m = type->create();
  try {
    type->from_json(nlohmann::json::parse(o.json), m);
  } catch (const std::exception& e) {
    type->destroy(m);
    throw std::invalid_argument(std::string("message: ") + e.what());
  }
  auto p = MakeParticipant(o.dds, "iplan-topic-pub");
  dds::AnyWriter writer(*p, topic, type->dds_name, qos);
  if (!writer.WaitForReaders(1, Seconds(o.wait_readers)) && o.count == 1) {
    std::cerr << "iplan topic pub: no reader of " << RosTopicName(topic) << " matched within " << o.wait_readers
              << " s; publishing anyway (a volatile topic's late readers will not see it; raise --wait-readers)\n";
  }
  InstallStop();
  const auto period = o.rate > 0 ? Seconds(1.0 / o.rate) : std::chrono::nanoseconds(0);
  auto next = Clock::now();
  int n = 0;
  int rc = 0;
  const bool has_header = type->to_json(m).contains("header");
  while (!g_stop && (o.count <= 0 || n < o.count)) {
    if (o.stamp_now && has_header) {
      nlohmann::json j = type->to_json(m);
      j["header"]["stamp"] = msg::ToJson(msg::Now());
      type->from_json(j, m);
    }
    std::string err;
    if (!writer.WriteAny(m, &err)) {
      std::cerr << "iplan topic pub: " << err << "\n";
      rc = 1;
      break;
    }
    ++n;
    if (o.count > 0 && n >= o.count) break;
    next += period;
    std::this_thread::sleep_until(next);
  }
  // Exit only once the matched readers have what was written: a reader whose
  // side of the discovery is still running (seconds on a loaded host) gets a
  // volatile sample by retransmission, which needs this writer alive.
  const auto ack_timeout = std::max<std::chrono::nanoseconds>(2s, Seconds(o.wait_readers));
  if (n > 0 && !writer.WaitForAcknowledgments(ack_timeout)) {
    std::cerr << "iplan topic pub: not every matched reader of " << RosTopicName(topic) << " acknowledged within "
              << std::chrono::duration<double>(ack_timeout).count() << " s; it may have missed the message\n";
  }
  type->destroy(m);
  std::cout << "published " << n << " message" << (n == 1 ? "" : "s") << " on " << RosTopicName(topic) << "\n";
  return rc;
}

void Register(CLI::App& app) {
  auto* topic = app.add_subcommand("topic", "Inspect and publish DDS topics (either vendor)");
  topic->require_subcommand(1);

  static ListOptions list;
  auto* l = topic->add_subcommand("list", "List the topics on the domain with their writers, readers and types");
  AddDdsOptions(l, &list.dds);
  l->add_option("--wait", list.wait, "seconds to listen for endpoints")->capture_default_str();
  l->add_flag("--all", list.all, "also list iplan topics nobody uses right now");
  l->callback([] { SetExitCode(RunList(list)); });

  static EchoOptions echo;
  auto* e = topic->add_subcommand("echo", "Print the messages of a topic as JSON, one per line");
  AddDdsOptions(e, &echo.dds);
  e->add_option("topic", echo.topic, "topic name, e.g. /iplan/human/skeleton")->required();
  e->add_option("--type", echo.type, "message type (default: from the iplan catalogue or discovery)");
  e->add_option("-n,--count", echo.count, "stop after this many messages (0: no limit)");
  e->add_option("--timeout", echo.timeout, "give up after this many seconds; exit 1 if nothing arrived");
  e->add_flag("--pretty", echo.pretty, "indent the JSON");
  e->callback([] { SetExitCode(RunEcho(echo)); });

  static HzOptions hz;
  auto* h = topic->add_subcommand("hz", "Print the receive rate of a topic every second");
  AddDdsOptions(h, &hz.dds);
  h->add_option("topic", hz.topic, "topic name")->required();
  h->add_option("--type", hz.type, "message type (default: from the catalogue or discovery)");
  h->add_option("-w,--window", hz.window, "messages in the statistics window")->capture_default_str();
  h->add_option("--duration", hz.duration, "stop after this many seconds (0: until Ctrl-C)");
  h->callback([] { SetExitCode(RunHz(hz)); });

  static PubOptions pub;
  auto* p = topic->add_subcommand("pub", "Publish a message given as JSON (fields not given keep defaults)");
  AddDdsOptions(p, &pub.dds);
  p->add_option("topic", pub.topic, "topic name")->required();
  p->add_option("message", pub.json, "the message as JSON; \"nan\", \"inf\" stand for non-finite numbers")->required();
  p->add_option("--type", pub.type, "message type (default: from the catalogue)");
  p->add_option("-r,--rate", pub.rate, "messages per second (with --count other than 1)");
  p->add_option("-n,--count", pub.count, "messages to publish (0: until Ctrl-C)")->capture_default_str();
  p->add_flag("--stamp-now", pub.stamp_now, "set header.stamp to the current time on every message");
  p->add_option("--wait-readers", pub.wait_readers,
                "seconds to wait for a reader before publishing, and at least 2 s afterwards for the readers to "
                "acknowledge (reliable topics)")
      ->capture_default_str();
  p->callback([] { SetExitCode(RunPub(pub)); });
}

const bool kRegistered = RegisterCommand("20-topic", Register);

}  // namespace
}  // namespace iplan::cli
