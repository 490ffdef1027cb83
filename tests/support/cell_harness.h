// The cell for multi-process tests, the one harness they share: the six
// services (or the few a test needs: the depth path's tests start the cloud
// service, collision risk, trajopt and the robot simulator) as separate
// processes with the shipped configuration (config/) and the test's extra
// arguments, the synthetic person of the demo cell, one DDS vendor, a
// domain and a state folder of their own, and an observer participant in
// the test process that records joint states, permits, task outcomes and
// diagnostics.
//
// Unlike `iplan demo`, every process is the test's own, so a test can kill,
// freeze (SIGSTOP) and restart any of them.
#pragma once

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "iplan/framework/node.h"
#include "test_node.h"
#include "test_paths.h"

namespace iplan::testing {

class CellHarness {
 public:
  using Clock = std::chrono::steady_clock;
  static const std::vector<std::string>& Services() {
    static const std::vector<std::string> kServices = {"perception", "intent",  "collision_risk",
                                                       "trajopt",    "robot_sim", "supervisor"};
    return kServices;
  }

  struct JointSample {
    Clock::time_point at;
    double max_speed = 0;  ///< rad/s, largest |qd| over the joints
  };
  struct PermitSample {
    Clock::time_point at;
    msg::SafetyPermit permit;
    std::string writer;
  };

  /// With a DDS Security keystore `security_dir` every service starts with
  /// --security and the observer uses enclave iplan-observer; without one
  /// every service starts with --insecure (unsecured on purpose). Either
  /// way the processes get IPLAN_SECURITY set to it (or emptied), so the
  /// environment the test runs in cannot change the cell.
  /// A test of a few services without intent (the depth path) passes
  /// `with_intent` false: no model is prepared, and starting intent fails.
  CellHarness(const std::string& tag, dds::Vendor vendor, int domain_offset, const std::string& security_dir = "",
              bool with_intent = true)
      : vendor_(vendor), domain_(UniqueDomain(domain_offset)), security_(security_dir) {
    // Per vendor: a test's second vendor must not delete the logs its first one kept.
    dir_ = std::filesystem::temp_directory_path() /
           ("iplan-" + tag + "-" + dds::ToString(vendor) + "-" + std::to_string(getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    config_dir_ = std::string(IPLAN_SOURCE_DIR) + "/config";
    // The cell's intent model, trained from the synthetic person on first
    // use and cached (as `iplan demo` does).
    if (with_intent) {
      Process prep({BinPath("iplan"), "demo", "--prepare-only", "--config-dir", config_dir_, "--state-dir", dir_.string()});
      const auto rc = prep.Wait(std::chrono::seconds(300));
      const std::string out = prep.Stdout();
      const auto at = out.find("model path: ");
      if (!rc || *rc != 0 || at == std::string::npos) {
        ADD_FAILURE() << "cannot prepare the cell's intent model:\n" << out << prep.Stderr();
        return;
      }
      model_ = out.substr(at + 12, out.find('\n', at) - at - 12);
    }
    observer_ = std::make_unique<TestNode>("observer", vendor, domain_, security_);
    framework::Node& node = *observer_->node;
    using SI = const dds::SampleInfo&;
    framework::SubscribeOptions any_order{false};
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, SI)>([this](const msg::JointState& m, SI) {
                     double v = 0;
                     for (double x : m.velocity) v = std::max(v, std::abs(x));
                     joints_.push_back({Clock::now(), v});
                     positions_ = m.position;
                   }),
                   any_order);
    for (const auto& topic : {framework::topics::SupervisorPermit(), framework::topics::CollisionRiskPermit()}) {
      node.Subscribe(topic, std::function<void(const msg::SafetyPermit&, SI)>([this](const msg::SafetyPermit& m, SI info) {
                       permits_.push_back({Clock::now(), m, info.writer_name});
                     }),
                     any_order);
    }
    node.Subscribe(framework::topics::TaskOutcome(),
                   std::function<void(const msg::TaskOutcome&, SI)>([this](const msg::TaskOutcome& m, SI) {
                     outcomes_.push_back(m);
                   }),
                   any_order);
    node.Subscribe(framework::topics::Diagnostics(),
                   std::function<void(const msg::DiagnosticArray&, SI)>([this](const msg::DiagnosticArray& a, SI) {
                     for (const auto& st : a.status) {
                       state_[st.name] = st.message;
                       ++diag_count_[st.name];
                       for (const auto& kv : st.values) diag_[st.name][kv.key] = kv.value;
                     }
                   }),
                   any_order);
  }

  ~CellHarness() {
    TerminateAll(false);
    procs_.clear();
    observer_.reset();
    // Service logs stay for a failed test (each start: <svc>-<n>.out/.err).
    if (::testing::Test::HasFailure()) {
      std::cout << "service logs kept in " << dir_.string() << "\n";
    } else {
      std::filesystem::remove_all(dir_);
    }
  }

  bool ready() const { return observer_ != nullptr; }
  dds::Vendor vendor() const { return vendor_; }
  /// The keystore the cell runs with ("" when unsecured).
  const std::string& security() const { return security_; }
  framework::Node& node() { return *observer_->node; }
  /// The observer's participant (for the test's own writers and readers).
  dds::Participant& participant() { return *observer_->participant; }
  int domain() const { return domain_; }
  /// The cell's folder: the services' logs (kept when the test failed) and
  /// whatever files the test writes for them.
  const std::filesystem::path& dir() const { return dir_; }
  std::string q_table() const { return (dir_ / "q_table.bin").string(); }
  /// The intent model the cell's intent service loads.
  const std::string& model() const { return model_; }

  /// Where `svc` runs from its next start: `launcher` goes before its
  /// command line (e.g. `ip netns exec <host>`), on `vendor`.
  void Place(const std::string& svc, std::vector<std::string> launcher, dds::Vendor vendor) {
    launchers_[svc] = std::move(launcher);
    vendors_[svc] = vendor;
  }

  /// Runs `svc` on `vendor` instead of the cell's (from its next Start).
  void SetVendor(const std::string& svc, dds::Vendor vendor) { vendors_[svc] = vendor; }

  /// Starts `svc` with the configuration file `path` (e.g. one the test
  /// wrote into dir()) instead of config/<svc>.yaml, and without the cell's
  /// own settings for it (intent's model, perception's synthetic person, the
  /// supervisor's Q-table): the file says everything (from its next Start).
  void Configure(const std::string& svc, const std::string& path) { configs_[svc] = path; }

  /// Writes `content` to dir()/`name` and returns its path.
  std::string WriteFile(const std::string& name, const std::string& content) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << content;
    return path;
  }

  /// Starts (or restarts) `svc` with the shipped configuration (or the file
  /// Configure gave) and `extra` arguments after it.
  void Start(const std::string& svc, const std::vector<std::string>& extra = {}) {
    const std::string exe = svc == "robot_sim" ? "robot-sim" : svc == "collision_risk" ? "collision-risk" : svc;
    const dds::Vendor vendor = vendors_.count(svc) ? vendors_.at(svc) : vendor_;
    std::vector<std::string> argv = launchers_[svc];
    const bool own_config = configs_.count(svc) > 0;
    argv.insert(argv.end(), {BinPath("iplan-" + exe), "--config",
                             own_config ? configs_.at(svc) : config_dir_ + "/" + svc + ".yaml", "--dds",
                             dds::ToString(vendor), "--domain", std::to_string(domain_)});
    if (security_.empty()) argv.push_back("--insecure");
    if (!security_.empty()) argv.insert(argv.end(), {"--security", security_});
    if (!own_config && !AddCellSettings(svc, &argv)) return;
    argv.insert(argv.end(), extra.begin(), extra.end());
    procs_[svc] = std::make_unique<Process>(argv, std::map<std::string, std::string>{{"IPLAN_SECURITY", security_}},
                                            false, (dir_ / (svc + "-" + std::to_string(++starts_))).string());
  }
  void StartAll() {
    for (const auto& s : Services()) Start(s);
  }
  /// Stops every service started; each must exit 0 on SIGTERM. Their logs
  /// stay readable (Logs) until a service is started again.
  void Stop() { TerminateAll(true); }
  Process& operator[](const std::string& svc) { return *procs_.at(svc); }
  std::string Logs(const std::string& svc) const {
    auto it = procs_.find(svc);
    return it == procs_.end() || !it->second ? "" : it->second->Stderr();
  }

  /// After a diagnostics period: the simulated robot never touched the
  /// person (since its last start), and every service exits 0 on SIGTERM.
  void ExpectNoContactAndCleanShutdown() {
    SpinFor(std::chrono::milliseconds(1500));
    EXPECT_EQ(DiagNumber("robot_sim", "true_contacts", -1), 0);
    for (const std::string& svc : Services()) {
      (*this)[svc].Signal(SIGTERM);
      EXPECT_EQ((*this)[svc].Wait(std::chrono::seconds(10)), 0) << svc << ":\n" << Logs(svc);
    }
  }

  /// Spins the observer until `done()` or `timeout`; returns done().
  bool SpinUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
    const auto end = Clock::now() + timeout;
    while (!done() && Clock::now() < end) node().SpinOnce(std::chrono::milliseconds(5));
    return done();
  }
  void SpinFor(std::chrono::milliseconds d) {
    SpinUntil([] { return false; }, d);
  }

  /// The arm moves faster than `speed` rad/s (newest joint state).
  bool Moving(double speed = 0.2) const { return !joints_.empty() && joints_.back().max_speed > speed; }
  /// Newest joint state is recent and at rest.
  bool AtRest(double speed = 1e-3) const {
    return !joints_.empty() && Clock::now() - joints_.back().at < std::chrono::milliseconds(200) &&
           joints_.back().max_speed < speed;
  }
  /// First joint state after `since` from which the arm stays at rest to the
  /// newest one (nullopt when it is not at rest now).
  std::optional<Clock::time_point> RestSince(Clock::time_point since, double speed = 1e-3) const {
    std::optional<Clock::time_point> rest;
    for (const auto& j : joints_) {
      if (j.at < since) continue;
      if (j.max_speed < speed) {
        if (!rest) rest = j.at;
      } else {
        rest.reset();
      }
    }
    return rest;
  }
  /// Largest joint speed seen after `since`.
  double MaxSpeedSince(Clock::time_point since) const {
    double v = 0;
    for (const auto& j : joints_) {
      if (j.at >= since) v = std::max(v, j.max_speed);
    }
    return v;
  }
  const std::vector<double>& positions() const { return positions_; }
  const std::vector<PermitSample>& permits() const { return permits_; }
  const std::vector<msg::TaskOutcome>& outcomes() const { return outcomes_; }
  /// The newest permit of `source` ("supervisor", "collision_risk") is PERMIT.
  bool Permits(const std::string& source) const {
    for (auto it = permits_.rbegin(); it != permits_.rend(); ++it) {
      if (it->permit.source == source) return it->permit.state == msg::SafetyPermit::PERMIT;
    }
    return false;
  }
  std::string LastReason(const std::string& source) const {
    for (auto it = permits_.rbegin(); it != permits_.rend(); ++it) {
      if (it->permit.source == source) return it->permit.reason;
    }
    return "(no permit from " + source + ")";
  }
  /// A diagnostics value of a service ("" when not seen).
  std::string Diag(const std::string& service, const std::string& key) const {
    auto s = diag_.find(service);
    if (s == diag_.end()) return "";
    auto k = s->second.find(key);
    return k == s->second.end() ? "" : k->second;
  }
  /// The newest diagnostics message of a service (its lifecycle state,
  /// e.g. "active"; "" when not seen).
  std::string State(const std::string& service) const {
    auto s = state_.find(service);
    return s == state_.end() ? "" : s->second;
  }
  /// How many diagnostics reports of a service came (one a period).
  int DiagCount(const std::string& service) const {
    auto s = diag_count_.find(service);
    return s == diag_count_.end() ? 0 : s->second;
  }
  double DiagNumber(const std::string& service, const std::string& key, double otherwise = 0) const {
    const std::string v = Diag(service, key);
    return v.empty() ? otherwise : std::stod(v);
  }

 private:
  // SIGTERM to every service started (SIGCONT first: a test may have
  // stopped one), then waits up to 10 s for each; with `expect_clean`, each
  // must have exited 0.
  void TerminateAll(bool expect_clean) {
    for (auto& [name, p] : procs_) {
      if (!p) continue;
      p->Signal(SIGCONT);
      p->Signal(SIGTERM);
    }
    for (auto& [name, p] : procs_) {
      if (!p) continue;
      const std::optional<int> code = p->Wait(std::chrono::seconds(10));
      if (expect_clean) {
        EXPECT_EQ(code, 0) << name << ":\n" << p->Stderr();
      }
    }
  }

  /// The cell's own settings for `svc` (shipped configuration): intent's
  /// model, perception's synthetic person, the supervisor's Q-table. False
  /// (and a test failure) for intent in a cell made without it.
  bool AddCellSettings(const std::string& svc, std::vector<std::string>* argv) const {
    if (svc == "intent") {
      if (model_.empty()) {
        ADD_FAILURE() << "intent started in a cell made without it";
        return false;
      }
      argv->insert(argv->end(), {"--set", "intent.model=" + model_});
    }
    if (svc == "perception") {
      argv->insert(argv->end(), {"--set", "perception.provider=synthetic", "--set", "perception.publish_truth=true"});
    }
    if (svc == "supervisor") {
      argv->insert(argv->end(), {"--set", "supervisor.q_table=" + q_table(), "--set", "supervisor.pause_between_tasks=0.2"});
    }
    return true;
  }

  dds::Vendor vendor_;
  int domain_;
  std::string security_;  ///< DDS Security keystore, or ""
  std::map<std::string, dds::Vendor> vendors_;  ///< services not on vendor_
  std::filesystem::path dir_;
  std::string config_dir_, model_;
  std::unique_ptr<TestNode> observer_;
  std::map<std::string, std::unique_ptr<Process>> procs_;
  std::map<std::string, std::vector<std::string>> launchers_;  ///< what runs each service (Place), or none
  int starts_ = 0;
  std::vector<JointSample> joints_;
  std::vector<double> positions_;
  std::vector<PermitSample> permits_;
  std::vector<msg::TaskOutcome> outcomes_;
  std::map<std::string, std::map<std::string, std::string>> diag_;
  std::map<std::string, std::string> state_;    ///< service -> newest diagnostics message
  std::map<std::string, int> diag_count_;       ///< service -> diagnostics reports seen
  std::map<std::string, std::string> configs_;  ///< services started with the test's own file (Configure)
};

}  // namespace iplan::testing
