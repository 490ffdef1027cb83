// iplan demo: starts the cell's services as separate processes on loopback
// DDS and reports what flows between them.
//
// Today the cell is the DDS spine: the perception service (synthetic person)
// publishes skeletons, and this process subscribes through the service
// framework (boundary checks, diagnostics) on the same or the other vendor.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "dds_common.h"
#include "iplan/core/process.h"
#include "iplan/core/stats.h"
#include "iplan/framework/node.h"

namespace iplan::cli {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

volatile sig_atomic_t g_stop = 0;

struct DemoOptions {
  std::string vendor;
  bool mixed = false;
  int domain = -1;
  double duration = 5.0;
  std::string summary_file;
};

int RunDemo(const DemoOptions& o) {
  const dds::Vendor service_vendor = o.vendor.empty() ? dds::DefaultVendor() : dds::ParseVendor(o.vendor);
  const dds::Vendor monitor_vendor =
      o.mixed ? (service_vendor == dds::Vendor::kCyclone ? dds::Vendor::kFastDds : dds::Vendor::kCyclone)
              : service_vendor;
  // A domain of its own so that the demo never talks to a running cell.
  const int domain = o.domain >= 0 ? o.domain : 100 + static_cast<int>(getpid() % 100);
  std::cout << "iplan demo: DDS spine on loopback, domain " << domain << "\n"
            << "  perception service: " << dds::ToString(service_vendor) << " (separate process)\n"
            << "  monitor (this process): " << dds::ToString(monitor_vendor) << "\n"
            << "  duration: " << o.duration << " s" << std::endl;

  const std::string bin = core::ExecutableDir();
  core::Process perception({bin + "/iplan-perception", "--dds", dds::ToString(service_vendor), "--domain",
                            std::to_string(domain)});

  dds::ParticipantOptions popts;
  popts.vendor = monitor_vendor;
  popts.domain_id = domain;
  popts.name = "iplan-demo";
  auto participant = dds::Participant::Create(popts);
  spdlog::set_level(spdlog::level::warn);  // the progress lines say what matters
  framework::NodeOptions nopts;
  nopts.diagnostics_period = 0;
  framework::Node node("demo", *participant, nopts);
  std::vector<double> latency_ms;
  uint64_t skeletons = 0;
  Clock::time_point first{}, last{};
  std::map<std::string, std::string> perception_diag;
  node.Subscribe(framework::topics::HumanSkeleton(),
                 std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                     [&](const msg::HumanSkeleton& s, const dds::SampleInfo& info) {
                       if (skeletons++ == 0) first = Clock::now();
                       last = Clock::now();
                       latency_ms.push_back((info.reception_ns - msg::ToNanoseconds(s.header.stamp)) * 1e-6);
                     }));
  node.Subscribe(framework::topics::Diagnostics(),
                 std::function<void(const msg::DiagnosticArray&, const dds::SampleInfo&)>(
                     [&](const msg::DiagnosticArray& a, const dds::SampleInfo&) {
                       for (const auto& st : a.status) {
                         if (st.name != "perception") continue;
                         for (const auto& kv : st.values) perception_diag[kv.key] = kv.value;
                       }
                     }));

  g_stop = 0;
  signal(SIGINT, [](int) { g_stop = 1; });
  const auto start = Clock::now();
  auto next_report = start + 1s;
  uint64_t last_count = 0;
  while (!g_stop && Clock::now() - start < std::chrono::duration<double>(o.duration)) {
    node.SpinOnce(50ms);
    if (!perception.Running()) break;
    if (Clock::now() >= next_report) {
      next_report += 1s;
      const auto s = core::Summarize(latency_ms);
      std::cout << "  t=" << std::fixed << std::setprecision(0)
                << std::chrono::duration<double>(Clock::now() - start).count() << " s  skeletons " << skeletons
                << " (+" << skeletons - last_count << "/s)  latency p50 " << std::setprecision(2) << s.p50
                << " ms  perception: " << (perception_diag.count("state") ? perception_diag["state"] : "starting")
                << std::endl;
      last_count = skeletons;
    }
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  // Rate over the time messages flowed (discovery takes a moment at start).
  const double flowing = std::chrono::duration<double>(last - first).count();
  const double rate = skeletons > 1 && flowing > 0 ? (skeletons - 1) / flowing : 0.0;
  perception.Signal(SIGTERM);
  const auto rc = perception.Wait(10s);
  const auto lat = core::Summarize(latency_ms);
  const auto stats = node.stats(framework::topics::HumanSkeleton().name);

  std::cout << "\nSummary\n"
            << "  skeletons received        " << skeletons << "\n"
            << "  rate                      " << std::setprecision(1) << rate << " Hz\n"
            << "  latency stamp->receive    p50 " << std::setprecision(3) << lat.p50 << " ms, p99 " << lat.p99
            << " ms, max " << lat.max << " ms\n"
            << "  rejected messages         " << stats.rejected << "\n"
            << "  deadline misses           " << stats.deadline_misses << "\n"
            << "  perception exit code      " << (rc ? std::to_string(*rc) : "did not stop") << std::endl;

  if (!o.summary_file.empty()) {
    nlohmann::json j;
    j["domain"] = domain;
    j["service_vendor"] = dds::ToString(service_vendor);
    j["monitor_vendor"] = dds::ToString(monitor_vendor);
    j["duration_s"] = elapsed;
    j["skeletons_received"] = skeletons;
    j["rate_hz"] = rate;
    j["latency_ms"] = {{"p50", lat.p50}, {"p99", lat.p99}, {"max", lat.max}};
    j["rejected_messages"] = stats.rejected;
    j["deadline_misses"] = stats.deadline_misses;
    j["perception_exit_code"] = rc ? *rc : -1;
    std::ofstream(o.summary_file) << j.dump(2) << "\n";
    std::cout << "  summary written to " << o.summary_file << std::endl;
  }
  if (!rc || *rc != 0) {
    std::cerr << "iplan demo: the perception service failed:\n" << perception.Stderr();
    return 1;
  }
  if (skeletons == 0) {
    std::cerr << "iplan demo: no skeleton arrived\n" << perception.Stderr();
    return 1;
  }
  return 0;
}

void Register(CLI::App& app) {
  static DemoOptions o;
  auto* d = app.add_subcommand("demo", "Run the cell's services as separate processes on loopback DDS and report");
  d->add_option("--dds", o.vendor, "DDS vendor of the services: cyclonedds or fastdds (default: $IPLAN_DDS, else cyclonedds)");
  d->add_flag("--mixed", o.mixed, "run the monitor on the other vendor (cross-vendor interop)");
  d->add_option("--domain", o.domain, "DDS domain (default: 100 + pid % 100, to stay apart from a running cell)")
      ->check(CLI::Range(0, 232));
  d->add_option("--duration", o.duration, "seconds to run")->capture_default_str()->check(CLI::PositiveNumber);
  d->add_option("--summary", o.summary_file, "write the summary as JSON to this file");
  d->callback([] { SetExitCode(RunDemo(o)); });
}

const bool kRegistered = RegisterCommand("10-demo", Register);

}  // namespace
}  // namespace iplan::cli
