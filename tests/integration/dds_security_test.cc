// DDS Security with real processes and real participants: a keystore made by
// `iplan security create-keystore`, iplan-perception and iplan-robot-sim
// started with --security, and around them
//  - a participant without credentials and one with another CA's credentials
//    (even claiming the entitled names iplan-trajopt and iplan-supervisor):
//    they read no skeleton, and robot-sim accepts none of their trajectories
//    and permits (its counters stay at zero: nothing even matches);
//  - a credentialed participant whose permissions do not grant the topic
//    (perception's enclave publishing a trajectory, the supervisor's
//    publishing collision risk's permit): its writer is refused;
//  - entitled, credentialed participants: the observer reads skeletons and
//    diagnostics, iplan-trajopt's enclave publishes a trajectory and
//    iplan-supervisor's a permit, and robot-sim accepts both.
// On Cyclone DDS, on Fast DDS, and mixed (services on Fast DDS, the clients on
// Cyclone DDS: the pairing whose handshake the two vendors complete; the
// other one fails, docs/dds.md "DDS Security").
// The whole cell (six services) secured completes tasks on each vendor.
// Also: a keystore's file modes, refusing to overwrite one, and services
// refusing a missing or tampered enclave with exit code 2.
#include <sys/stat.h>

#include <filesystem>
#include <map>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "iplan/core/atomic_file.h"
#include "iplan/dds/participant.h"
#include "iplan/framework/node.h"
#include "iplan/framework/topics.h"
#include "iplan/msg/json.h"
#include "cell_harness.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

unsigned Mode(const fs::path& p) {
  struct stat st{};
  EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
  return st.st_mode & 07777;
}

// Two keystores (two CAs) for the whole test program.
class Keystores : public ::testing::Environment {
 public:
  static fs::path Dir() { return fs::temp_directory_path() / ("iplan-sec-" + std::to_string(getpid())); }
  static std::string Cell() { return (Dir() / "cell").string(); }
  static std::string Other() { return (Dir() / "other").string(); }
  void SetUp() override {
    fs::remove_all(Dir());
    fs::create_directories(Dir());
    for (const auto& d : {Cell(), Other()}) {
      Process p({BinPath("iplan"), "security", "create-keystore", d});
      ASSERT_EQ(p.Wait(60s), 0) << p.Stdout() << p.Stderr();
    }
  }
  void TearDown() override { fs::remove_all(Dir()); }
};
const auto* const kKeystores = ::testing::AddGlobalTestEnvironment(new Keystores);

TEST(SecurityKeystore, KeysAreTheOwnersAloneAndAKeystoreIsNeverOverwritten) {
  const fs::path k = Keystores::Cell();
  EXPECT_EQ(Mode(k / "private"), 0700u);
  EXPECT_EQ(Mode(k / "private/ca.key.pem"), 0600u);
  int enclaves = 0;
  for (const auto& e : fs::directory_iterator(k / "enclaves")) {
    if (!e.is_directory()) continue;
    ++enclaves;
    EXPECT_EQ(Mode(e.path() / "key.pem"), 0600u) << e.path();
    for (const char* f : {"cert.pem", "identity_ca.cert.pem", "permissions_ca.cert.pem", "governance.p7s",
                          "permissions.p7s", "permissions.xml"}) {
      EXPECT_TRUE(fs::is_regular_file(e.path() / f)) << e.path() / f;
    }
  }
  EXPECT_EQ(enclaves, 8);  // seven services (cloud included) and the observer
  // No temporaries left beside it.
  for (const auto& e : fs::directory_iterator(Keystores::Dir())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  }
  const auto before = fs::last_write_time(k / "private/ca.key.pem");
  Process again({BinPath("iplan"), "security", "create-keystore", k.string()});
  EXPECT_EQ(again.Wait(30s), 1);
  EXPECT_NE(again.Stderr().find("exists and is not empty"), std::string::npos) << again.Stderr();
  EXPECT_EQ(fs::last_write_time(k / "private/ca.key.pem"), before);
  Process check({BinPath("iplan"), "security", "check", k.string()});
  EXPECT_EQ(check.Wait(30s), 0) << check.Stdout();
}

TEST(SecurityKeystore, ServicesRefuseAMissingOrTamperedEnclave) {
  // No keystore at all.
  Process none({BinPath("iplan-robot-sim"), "--security", (Keystores::Dir() / "nothing").string()});
  EXPECT_EQ(none.Wait(30s), 2);
  EXPECT_NE(none.Stderr().find("is not a folder"), std::string::npos) << none.Stderr();
  // The same through IPLAN_SECURITY (what the systemd units set), and a
  // valid keystore through it.
  Process env_none({BinPath("iplan-robot-sim"), "--check-config"},
                   {{"IPLAN_SECURITY", (Keystores::Dir() / "nothing").string()}});
  EXPECT_EQ(env_none.Wait(30s), 2);
  EXPECT_NE(env_none.Stderr().find("is not a folder"), std::string::npos) << env_none.Stderr();
  Process env_ok({BinPath("iplan-robot-sim"), "--check-config", "--domain", std::to_string(UniqueDomain(121))},
                 {{"IPLAN_SECURITY", Keystores::Cell()}});
  EXPECT_EQ(env_ok.Wait(30s), 0) << env_ok.Stderr();
  EXPECT_NE(env_ok.Stderr().find("DDS Security enclave iplan-robot_sim of " + Keystores::Cell()), std::string::npos)
      << env_ok.Stderr();
  // A keystore without the service's enclave.
  const fs::path partial = Keystores::Dir() / "partial";
  fs::copy(Keystores::Cell(), partial, fs::copy_options::recursive);
  fs::remove_all(partial / "enclaves/iplan-robot_sim");
  Process missing({BinPath("iplan-robot-sim"), "--security", partial.string()});
  EXPECT_EQ(missing.Wait(30s), 2);
  EXPECT_NE(missing.Stderr().find("enclave iplan-robot_sim"), std::string::npos) << missing.Stderr();
  // Permissions edited after signing (a topic added to perception's grant).
  const fs::path p7s = partial / "enclaves/iplan-perception/permissions.p7s";
  std::string doc = core::ReadFile(p7s.string());
  const auto at = doc.find("<topic>rt/diagnostics</topic>");
  ASSERT_NE(at, std::string::npos);
  doc.insert(at, "<topic>rt/iplan/robot/trajectory</topic>");
  std::ofstream(p7s) << doc;
  Process tampered({BinPath("iplan-perception"), "--security", partial.string()});
  EXPECT_EQ(tampered.Wait(30s), 2);
  EXPECT_NE(tampered.Stderr().find("does not verify"), std::string::npos) << tampered.Stderr();
  // A private key others may read.
  fs::permissions(partial / "enclaves/iplan-intent/key.pem", fs::perms::others_read, fs::perm_options::add);
  Process loose({BinPath("iplan"), "security", "check", partial.string(), "iplan-intent"});
  EXPECT_EQ(loose.Wait(30s), 1);
  EXPECT_NE(loose.Stdout().find("chmod 600"), std::string::npos) << loose.Stdout();
}

// Each service creates every reader and writer at configuration: with
// --check-config it authenticates as its enclave and the vendor's access
// control allows (or refuses) each topic its node creates. Intent is left
// out (it needs a trained model first).
TEST(SecurityKeystore, EveryServiceConfiguresWithItsEnclaveOnBothVendors) {
  for (const char* vendor : {"cyclonedds", "fastdds"}) {
    for (const char* svc : {"perception", "collision-risk", "trajopt", "robot-sim", "supervisor"}) {
      Process p({BinPath(std::string("iplan-") + svc), "--check-config", "--dds", vendor, "--domain",
                 std::to_string(UniqueDomain(120)), "--security", Keystores::Cell()});
      EXPECT_EQ(p.Wait(60s), 0) << svc << " on " << vendor << ":\n" << p.Stdout() << p.Stderr();
    }
  }
  // Another service's grant is not enough: trajopt's node under perception's
  // permissions (a copy of the keystore with the two enclaves swapped would
  // need re-signing; instead perception's enclave is renamed to trajopt's,
  // whose certificate subject then does not match).
  const fs::path swapped = Keystores::Dir() / "swapped";
  fs::copy(Keystores::Cell(), swapped, fs::copy_options::recursive);
  fs::remove_all(swapped / "enclaves/iplan-trajopt");
  fs::rename(swapped / "enclaves/iplan-perception", swapped / "enclaves/iplan-trajopt");
  Process p({BinPath("iplan-trajopt"), "--check-config", "--security", swapped.string()});
  EXPECT_EQ(p.Wait(60s), 2);
  EXPECT_NE(p.Stderr().find("is for CN=iplan-perception, not CN=iplan-trajopt"), std::string::npos) << p.Stderr();
}

// Secure by default: a service without a keystore says so; with
// --require-security (what the units pass) or as a supervisor in deployment
// mode it refuses to start (exit code 2, the reason said) unless --insecure
// or IPLAN_INSECURE=1 says it is meant; --insecure with a keystore is a
// contradiction.
TEST(SecurityMode, ServicesRefuseToRunUnsecuredUnlessToldSo) {
  const std::string domain = std::to_string(UniqueDomain(122));
  const std::map<std::string, std::string> no_env = {{"IPLAN_SECURITY", ""}, {"IPLAN_INSECURE", ""}};
  Process unit({BinPath("iplan-robot-sim"), "--require-security", "--check-config", "--domain", domain}, no_env);
  EXPECT_EQ(unit.Wait(30s), 2);
  EXPECT_NE(unit.Stderr().find("refusing to start without DDS Security (--require-security"), std::string::npos)
      << unit.Stderr();
  const std::string q_table = "supervisor.q_table=" + (Keystores::Dir() / "q.bin").string();
  Process deployed({BinPath("iplan-supervisor"), "--set", "supervisor.mode=deployment", "--set", q_table,
                    "--check-config", "--domain", domain},
                   no_env);
  EXPECT_EQ(deployed.Wait(30s), 2);
  EXPECT_NE(deployed.Stderr().find("refusing to start without DDS Security (supervisor.mode is deployment)"),
            std::string::npos)
      << deployed.Stderr();
  auto env = no_env;
  env["IPLAN_INSECURE"] = "1";
  Process meant({BinPath("iplan-supervisor"), "--set", "supervisor.mode=deployment", "--set", q_table,
                 "--require-security", "--check-config", "--domain", domain},
                env);
  EXPECT_EQ(meant.Wait(30s), 0) << meant.Stderr();
  EXPECT_NE(meant.Stderr().find("DDS Security is off on purpose (--insecure)"), std::string::npos) << meant.Stderr();
  Process secured({BinPath("iplan-supervisor"), "--set", "supervisor.mode=deployment", "--set", q_table,
                   "--require-security", "--check-config", "--domain", domain, "--security", Keystores::Cell()},
                  no_env);
  EXPECT_EQ(secured.Wait(60s), 0) << secured.Stderr();
  Process both({BinPath("iplan-robot-sim"), "--insecure", "--security", Keystores::Cell(), "--check-config"}, no_env);
  EXPECT_EQ(both.Wait(30s), 2);
  EXPECT_NE(both.Stderr().find("contradicts the DDS Security keystore"), std::string::npos) << both.Stderr();
}

// A Cyclone DDS service and a Fast DDS client of one secured cell cannot
// authenticate (Debian's builds): the service says so, with the reason, once.
TEST(MixedVendors, ACycloneServiceExplainsTheFailedFastDdsHandshake) {
  const std::string domain = std::to_string(UniqueDomain(123));
  Process svc({BinPath("iplan-perception"), "--dds", "cyclonedds", "--domain", domain, "--security", Keystores::Cell()});
  Process client({BinPath("iplan"), "topic", "echo", "/iplan/human/skeleton", "-n", "1", "--timeout", "20", "--dds",
                  "fastdds", "--domain", domain, "--security", Keystores::Cell()});
  const std::string expected = "iplan: the DDS Security handshake above failed the way Debian's Fast DDS 2.9 and "
                               "Cyclone DDS 0.10 fail with each other";
  const auto end = Clock::now() + 20s;
  while (svc.Stderr().find(expected) == std::string::npos && Clock::now() < end) std::this_thread::sleep_for(100ms);
  client.Signal(SIGTERM);
  svc.Signal(SIGTERM);
  EXPECT_EQ(svc.Wait(15s), 0);
  const std::string log = svc.Stderr();
  EXPECT_NE(log.find("ASN1 integer"), std::string::npos) << log;
  const auto first = log.find(expected);
  EXPECT_NE(first, std::string::npos) << log;
  EXPECT_EQ(log.find(expected, first + 1), std::string::npos) << "explained more than once:\n" << log;
}

struct Variant {
  std::string name;
  std::string services;  ///< vendor of the services
  std::string clients;   ///< vendor of every other participant
};

std::string TrajectoryJson() {
  msg::JointTrajectory t;
  t.header.frame_id = "world";
  for (int j = 1; j <= 7; ++j) t.joint_names.push_back("panda_joint" + std::to_string(j));
  for (int k = 0; k < 5; ++k) {
    msg::JointTrajectoryPoint pt;
    pt.positions = {0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8};
    pt.time_from_start = msg::DurationFromSeconds(0.1 * k);
    t.points.push_back(pt);
  }
  return msg::ToJson(t).dump();
}

std::string PermitJson() {
  msg::SafetyPermit p;
  p.state = msg::SafetyPermit::PERMIT;
  p.validity = 0.2;
  p.source = "supervisor";
  p.reason = "all inputs healthy";
  return msg::ToJson(p).dump();
}

class SecuredCell : public ::testing::TestWithParam<Variant> {
 protected:
  // Perception and robot-sim on the services' vendor; the observer (enclave
  // iplan-observer) on the clients', counting skeletons.
  void SetUp() override {
    cell_ = std::make_unique<CellHarness>("sec-cell-" + GetParam().name, dds::ParseVendor(GetParam().clients),
                                          140 + static_cast<int>(GetParam().name.size()), Keystores::Cell(),
                                          /*with_intent=*/false);
    ASSERT_TRUE(cell_->ready());
    cell_->node().Subscribe(framework::topics::HumanSkeleton(),
                            std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                                [this](const msg::HumanSkeleton&, const dds::SampleInfo&) { ++skeletons_; }));
    for (const char* svc : {"perception", "robot_sim"}) {
      cell_->SetVendor(svc, dds::ParseVendor(GetParam().services));
      cell_->Start(svc);
    }
  }
  void TearDown() override {
    if (cell_) cell_->Stop();
  }
  // robot-sim's diagnostic counter `key` (-1: not reported yet).
  long Robot(const std::string& key) const { return std::lround(cell_->DiagNumber("robot_sim", key, -1)); }
  // `iplan ARGS` on the clients' vendor and the cell's domain; `security`:
  // keystore and enclave, or empty for a participant without credentials.
  std::unique_ptr<Process> Tool(std::vector<std::string> args, const std::string& keystore = "",
                                const std::string& enclave = "") {
    args.insert(args.begin(), BinPath("iplan"));
    args.insert(args.end(), {"--dds", GetParam().clients, "--domain", std::to_string(cell_->domain())});
    if (!keystore.empty()) args.insert(args.end(), {"--security", keystore, "--enclave", enclave});
    return std::make_unique<Process>(args);
  }
  // Publishes `json` on `topic` at 20 Hz for 2 s.
  std::unique_ptr<Process> Publish(const std::string& topic, const std::string& json, const std::string& keystore,
                                   const std::string& enclave) {
    return Tool({"topic", "pub", topic, json, "--stamp-now", "-r", "20", "-n", "40", "--wait-readers", "3"}, keystore,
                enclave);
  }
  std::unique_ptr<CellHarness> cell_;
  int skeletons_ = 0;
};

TEST_P(SecuredCell, StrangersNeitherReadNorCommandEntitledParticipantsDo) {
  CellHarness& cell = *cell_;
  // The entitled observer reads skeletons and robot-sim's diagnostics.
  ASSERT_TRUE(cell.SpinUntil([&] { return skeletons_ >= 5 && cell.DiagCount("robot_sim") >= 1; }, 40s))
      << "skeletons " << skeletons_ << ", robot-sim diagnostics " << cell.DiagCount("robot_sim") << "\n"
      << cell.Logs("perception") << cell.Logs("robot_sim");
  const std::string traj_topic = framework::topics::RobotTrajectory().name;
  const std::string permit_topic = framework::topics::SupervisorPermit().name;
  EXPECT_EQ(Robot("received/" + traj_topic), 0);
  EXPECT_EQ(Robot("received/" + permit_topic), 0);

  // Strangers reading: no skeleton within 8 s (exit 1: nothing arrived).
  auto bare_echo = Tool({"topic", "echo", "/iplan/human/skeleton", "-n", "1", "--timeout", "8", "--type",
                         "iplan_msgs::msg::dds_::HumanSkeleton_"});
  auto other_echo = Tool({"topic", "echo", "/iplan/human/skeleton", "-n", "1", "--timeout", "8"}, Keystores::Other(),
                         "iplan-observer");
  // Strangers commanding, claiming the entitled names with the other CA.
  auto bare_traj = Publish(traj_topic, TrajectoryJson(), "", "");
  auto bare_permit = Publish(permit_topic, PermitJson(), "", "");
  auto other_traj = Publish(traj_topic, TrajectoryJson(), Keystores::Other(), "iplan-trajopt");
  auto other_permit = Publish(permit_topic, PermitJson(), Keystores::Other(), "iplan-supervisor");
  // Credentialed but not granted: perception may not publish trajectories,
  // nor the supervisor collision risk's permits (a permit's topic is its
  // monitor's authenticated identity).
  auto ungranted = Publish(traj_topic, TrajectoryJson(), Keystores::Cell(), "iplan-perception");
  const std::string risk_permit = framework::topics::CollisionRiskPermit().name;
  auto other_monitor = Publish(risk_permit, PermitJson(), Keystores::Cell(), "iplan-supervisor");
  EXPECT_EQ(bare_echo->Wait(30s), 1) << bare_echo->Stdout().substr(0, 300);
  EXPECT_EQ(bare_echo->Stdout(), "");
  EXPECT_EQ(other_echo->Wait(30s), 1) << other_echo->Stdout().substr(0, 300);
  EXPECT_EQ(other_echo->Stdout(), "");
  for (auto* p : {bare_traj.get(), bare_permit.get(), other_traj.get(), other_permit.get()}) {
    EXPECT_TRUE(p->Wait(30s).has_value());
  }
  EXPECT_NE(ungranted->Wait(30s), 0);
  EXPECT_NE(ungranted->Stderr().find(traj_topic), std::string::npos) << ungranted->Stderr();
  EXPECT_NE(other_monitor->Wait(30s), 0);
  EXPECT_NE(other_monitor->Stderr().find(risk_permit), std::string::npos) << other_monitor->Stderr();
  // Two more diagnostics periods: robot-sim received nothing and ignored
  // nobody (no stranger's writer ever matched its readers).
  const int seen = cell.DiagCount("robot_sim");
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.DiagCount("robot_sim") >= seen + 2; }, 10s));
  EXPECT_EQ(Robot("received/" + traj_topic), 0);
  EXPECT_EQ(Robot("received/" + permit_topic), 0);
  EXPECT_EQ(Robot("ignored_writers"), 0);

  // Entitled, credentialed writers: robot-sim accepts their trajectory and permits.
  auto traj = Publish(traj_topic, TrajectoryJson(), Keystores::Cell(), "iplan-trajopt");
  auto permit = Publish(permit_topic, PermitJson(), Keystores::Cell(), "iplan-supervisor");
  EXPECT_EQ(traj->Wait(30s), 0) << traj->Stderr();
  EXPECT_EQ(permit->Wait(30s), 0) << permit->Stderr();
  EXPECT_TRUE(cell.SpinUntil([&] {
    return Robot("received/" + traj_topic) >= 1 && Robot("received/" + permit_topic) >= 10;
  }, 10s)) << "trajectories " << Robot("received/" + traj_topic) << ", permits "
           << Robot("received/" + permit_topic);
  EXPECT_EQ(Robot("ignored_writers"), 0);
  EXPECT_EQ(Robot("rejected/" + permit_topic), 0);
}

INSTANTIATE_TEST_SUITE_P(Vendors, SecuredCell,
                         ::testing::Values(Variant{"cyclonedds", "cyclonedds", "cyclonedds"},
                                           Variant{"fastdds", "fastdds", "fastdds"},
                                           Variant{"mixed", "fastdds", "cyclonedds"}),
                         [](const auto& info) { return info.param.name; });
// Cyclone DDS services with Fast DDS clients: fails on Debian 12's builds
// (Cyclone: "Begin handshake reply failed: Failed to convert octet sequence
// to ASN1 integer"; the vendors encode the DH public key differently,
// docs/dds.md). Disabled; run it with --gtest_also_run_disabled_tests.
INSTANTIATE_TEST_SUITE_P(DISABLED_KnownFailure, SecuredCell,
                         ::testing::Values(Variant{"mixed_cyclone_services", "cyclonedds", "fastdds"}),
                         [](const auto& info) { return info.param.name; });

// The whole cell, every service under its own enclave and the observer
// under iplan-observer: the arm moves, tasks succeed, nobody is touched, and
// every service stops cleanly. On each vendor; mixed (perception and
// robot-sim on Fast DDS, everything else on Cyclone DDS: the split in which
// every Cyclone participant begins its handshakes with Fast DDS ones,
// docs/dds.md) passed 3 of 5 runs and is kept disabled below.
class SecuredEpisode : public ::testing::TestWithParam<std::string> {};

TEST_P(SecuredEpisode, TheWholeCellCompletesTasks) {
  const bool mixed = GetParam() == "mixed";
  CellHarness cell("sec-episode-" + GetParam(), mixed ? dds::Vendor::kCyclone : dds::ParseVendor(GetParam()), 60,
                   Keystores::Cell());
  ASSERT_TRUE(cell.ready());
  if (mixed) {
    cell.SetVendor("perception", dds::Vendor::kFastDds);
    cell.SetVendor("robot_sim", dds::Vendor::kFastDds);
  }
  const auto start = Clock::now();
  cell.StartAll();
  ASSERT_TRUE(cell.SpinUntil([&] { return cell.Moving(); }, 120s))
      << "the arm never moved; supervisor: " << cell.LastReason("supervisor") << "\n"
      << cell.Logs("supervisor") << cell.Logs("trajopt") << cell.Logs("intent");
  const auto succeeded = [&] {
    int n = 0;
    for (const auto& o : cell.outcomes()) n += o.status == msg::TaskOutcome::SUCCEEDED;
    return n;
  };
  EXPECT_TRUE(cell.SpinUntil([&] { return succeeded() >= 2; }, 180s))
      << succeeded() << " tasks succeeded of " << cell.outcomes().size() << " outcomes";
  std::cout << GetParam() << ", secured: " << succeeded() << " tasks succeeded "
            << std::chrono::duration<double>(Clock::now() - start).count() << " s after the services started\n";
  cell.ExpectNoContactAndCleanShutdown();
}

INSTANTIATE_TEST_SUITE_P(Vendors, SecuredEpisode, ::testing::Values("cyclonedds", "fastdds"),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(DISABLED_Flaky, SecuredEpisode, ::testing::Values("mixed"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace iplan::testing
