// cell_forger: an attacker on a cell's DDS domain, for multi-process tests.
// One participant per name given with --as, each *claiming* that name (its
// writers announce it in USER_DATA, as iplan's services do), publishing what
// that service publishes, forged:
//   iplan-supervisor      PERMITs on its permit topic (validity 5 s), CANCEL
//                         of --task on the task command topic
//   iplan-collision_risk  PERMITs on its permit topic, "OK" verdicts
//   iplan-trajopt         a trajectory moving joint 1 away from --joints
//                         (10 Hz), SUCCEEDED outcomes of --task
// With --security DIR --enclave E every participant authenticates as
// enclave E of keystore DIR (whatever name it claims).
//
//   cell_forger --dds V --domain D --as iplan-supervisor --as iplan-trajopt
//       [--security DIR --enclave E] [--rate 50] [--for 3] [--task ID]
//       [--joints q1,...,q7]
//
// Prints "refused <topic>: <why>" for every writer the vendor refuses (its
// access control), "matched <topic> <n>" whenever a writer's matched readers
// change, then "ready". The attack starts on SIGUSR1: PERMITs and verdicts
// at --rate for --for seconds, the others as said above. Then it prints
// "sent <topic> <n> matched <m>" per writer and "done", tries to delete its
// participants for at most 3 s and leaves with _exit: a forger never keeps
// the test waiting on a vendor's teardown (Fast DDS 2.9 once hung deleting a
// writer the cell's readers still talked to). SIGTERM ends it at any time.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <iostream>
#include <map>
#include <memory>
#include <thread>

#include <CLI/CLI.hpp>

#include "iplan/dds/participant.h"
#include "iplan/framework/topics.h"
#include "iplan/msg/time.h"

using namespace iplan;
using namespace std::chrono_literals;

namespace {

volatile sig_atomic_t g_go = 0, g_stop = 0;

struct Options {
  std::string vendor = "cyclonedds";
  int domain = 0;
  std::vector<std::string> names;
  std::string security, enclave;
  double rate = 50, seconds = 3;
  uint32_t task = 0;
  std::vector<double> joints = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};
};

// One claimed identity: its participant and the writers it got.
struct Forger {
  std::string name;
  std::unique_ptr<dds::Participant> participant;
  std::map<std::string, std::unique_ptr<dds::AnyWriter>> writers;  // by topic
  std::map<std::string, int> sent, matched;
};

template <class T>
void Advertise(Forger& f, const framework::Topic<T>& topic) {
  try {
    f.writers[topic.name] = std::make_unique<dds::Writer<T>>(*f.participant, topic.name, topic.qos);
  } catch (const std::exception& e) {
    std::cout << "refused " << topic.name << ": " << e.what() << std::endl;
  }
}

template <class T>
void Write(Forger& f, const framework::Topic<T>& topic, const T& m) {
  auto it = f.writers.find(topic.name);
  if (it == f.writers.end()) return;
  static_cast<dds::Writer<T>&>(*it->second).Write(m);
  ++f.sent[topic.name];
}

Forger MakeForger(const Options& o, const std::string& name) {
  Forger f;
  f.name = name;
  dds::ParticipantOptions p;
  p.vendor = dds::ParseVendor(o.vendor);
  p.domain_id = o.domain;
  p.name = name;
  p.security_dir = o.security;
  p.enclave = o.enclave;
  f.participant = dds::Participant::Create(p);
  namespace t = framework::topics;
  if (name == "iplan-supervisor") {
    Advertise(f, t::SupervisorPermit());
    Advertise(f, t::TaskCommand());
  } else if (name == "iplan-collision_risk") {
    Advertise(f, t::CollisionRiskPermit());
    Advertise(f, t::CollisionRisk());
  } else if (name == "iplan-trajopt") {
    Advertise(f, t::RobotTrajectory());
    Advertise(f, t::TaskOutcome());
  }
  return f;
}

msg::SafetyPermit Permit(const std::string& source) {
  msg::SafetyPermit p;
  p.header.stamp = msg::Now();
  p.state = msg::SafetyPermit::PERMIT;
  p.validity = 5;
  p.source = source;
  p.reason = "all inputs healthy";
  return p;
}

msg::JointTrajectory Away(const std::vector<double>& q) {
  msg::JointTrajectory t;
  t.header.stamp = msg::Now();
  t.header.frame_id = "world";
  for (int j = 1; j <= 7; ++j) t.joint_names.push_back("panda_joint" + std::to_string(j));
  for (int k = 0; k <= 10; ++k) {
    msg::JointTrajectoryPoint pt;
    pt.positions = q;
    pt.positions[0] += 0.05 * k;
    pt.time_from_start = msg::DurationFromSeconds(0.1 * k);
    t.points.push_back(pt);
  }
  return t;
}

// One step of the attack (`k` counts steps at --rate).
void Attack(const Options& o, Forger& f, int k) {
  namespace t = framework::topics;
  const int per_10hz = std::max(1, static_cast<int>(o.rate / 10));
  if (f.name == "iplan-supervisor") {
    Write(f, t::SupervisorPermit(), Permit("supervisor"));
    if (o.task != 0 && k % per_10hz == 0) {
      msg::TaskCommand c;
      c.header.stamp = msg::Now();
      c.task_id = o.task;
      c.command = msg::TaskCommand::CANCEL;
      Write(f, t::TaskCommand(), c);
    }
  } else if (f.name == "iplan-collision_risk") {
    Write(f, t::CollisionRiskPermit(), Permit("collision_risk"));
    msg::CollisionRisk v;
    v.header.stamp = msg::Now();
    v.header.frame_id = "world";
    v.verdict = msg::CollisionRisk::OK;
    v.reason = "clear";
    Write(f, t::CollisionRisk(), v);
  } else if (f.name == "iplan-trajopt" && k % per_10hz == 0) {
    Write(f, t::RobotTrajectory(), Away(o.joints));
    if (o.task != 0) {
      msg::TaskOutcome r;
      r.header.stamp = msg::Now();
      r.task_id = o.task;
      r.status = msg::TaskOutcome::SUCCEEDED;
      r.delay = 0.1;
      Write(f, t::TaskOutcome(), r);
    }
  }
}

void ReportMatches(std::vector<Forger>& forgers) {
  for (Forger& f : forgers) {
    for (auto& [topic, w] : f.writers) {
      const int n = w->MatchedReaders();
      auto it = f.matched.find(topic);
      if (it != f.matched.end() && it->second == n) continue;
      f.matched[topic] = n;
      std::cout << "matched " << topic << " " << n << std::endl;
    }
  }
}

int Run(const Options& o) {
  std::vector<Forger> forgers;
  for (const std::string& name : o.names) forgers.push_back(MakeForger(o, name));
  std::cout << "ready" << std::endl;
  while (!g_go && !g_stop) {
    ReportMatches(forgers);
    std::this_thread::sleep_for(50ms);
  }
  const auto period = std::chrono::nanoseconds(static_cast<int64_t>(1e9 / o.rate));
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  for (int k = 0; !g_stop && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(o.seconds); ++k) {
    for (Forger& f : forgers) Attack(o, f, k);
    next += period;
    std::this_thread::sleep_until(next);
  }
  ReportMatches(forgers);
  for (Forger& f : forgers) {
    for (auto& [topic, w] : f.writers) {
      std::cout << "sent " << topic << " " << f.sent[topic] << " matched " << w->MatchedReaders() << "\n";
    }
  }
  std::cout << "done" << std::endl;
  // Delete the participants on a thread of their own, for at most 3 s.
  auto* doomed = new std::vector<Forger>(std::move(forgers));
  auto* deleted = new std::atomic<bool>(false);
  std::thread([doomed, deleted] {
    delete doomed;
    *deleted = true;
  }).detach();
  for (int i = 0; i < 60 && !*deleted; ++i) std::this_thread::sleep_for(50ms);
  if (!*deleted) std::cout << "teardown unfinished after 3 s: leaving without it" << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cell_forger: forged samples under claimed service names (see the header of cell_forger.cc)"};
  Options o;
  std::string joints;
  app.add_option("--dds", o.vendor);
  app.add_option("--domain", o.domain);
  app.add_option("--as", o.names)->required();
  app.add_option("--security", o.security);
  app.add_option("--enclave", o.enclave);
  app.add_option("--rate", o.rate)->check(CLI::Range(1.0, 1000.0));
  app.add_option("--for", o.seconds)->check(CLI::Range(0.1, 60.0));
  app.add_option("--task", o.task);
  app.add_option("--joints", o.joints)->delimiter(',')->expected(7);
  CLI11_PARSE(app, argc, argv);
  signal(SIGUSR1, [](int) { g_go = 1; });
  signal(SIGTERM, [](int) { g_stop = 1; });
  signal(SIGINT, [](int) { g_stop = 1; });
  int rc = 0;
  try {
    rc = Run(o);
  } catch (const std::exception& e) {
    std::cerr << "cell_forger: " << e.what() << std::endl;
    rc = 2;
  }
  std::cout.flush();
  _exit(rc);
}
