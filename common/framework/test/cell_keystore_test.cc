// The cell's keystore and grants without DDS: who may publish which permit
// topic, and EnsureCellKeystore (create once and atomically, never trust a
// killed creation's leftovers, re-issue invalid or outdated enclaves, leave
// good ones alone).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <gtest/gtest.h>

#include "iplan/dds/security.h"
#include "iplan/framework/enclaves.h"
#include "iplan/framework/topics.h"

namespace iplan::framework {
namespace {

namespace fs = std::filesystem;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

bool Has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }

const dds::EnclaveGrant& Grant(const std::vector<dds::EnclaveGrant>& grants, const std::string& name) {
  return *std::find_if(grants.begin(), grants.end(), [&](const auto& g) { return g.name == name; });
}

TEST(PermitTopics, EachMonitorHasItsOwnTopicEntitledToItAlone) {
  const auto sup = topics::SafetyPermit("iplan-supervisor");
  EXPECT_EQ(sup.name, "rt/iplan/safety/permit/supervisor");
  EXPECT_EQ(sup.writers, std::vector<std::string>{"iplan-supervisor"});
  EXPECT_EQ(topics::CollisionRiskPermit().name, "rt/iplan/safety/permit/collision_risk");
  EXPECT_EQ(topics::SafetyPermit("acme-light.curtain").name, "rt/iplan/safety/permit/acme_light_curtain");
  EXPECT_THROW(topics::SafetyPermit(""), std::invalid_argument);
  EXPECT_THROW(topics::SafetyPermit("iplan-9lives"), std::invalid_argument);  // a token may not start with a digit
  EXPECT_THROW(topics::SafetyPermit("a b"), std::invalid_argument);
}

// With DDS Security a permit's topic is its authenticated origin: exactly
// one enclave is granted to publish each monitor's permits, and the command
// topics have one writer enclave each.
TEST(CellEnclaves, AuthorityIsGrantedToOneIdentityPerTopic) {
  const auto grants = CellEnclaves();
  const std::map<std::string, std::string> only_writer = {
      {topics::SupervisorPermit().name, "iplan-supervisor"},
      {topics::CollisionRiskPermit().name, "iplan-collision_risk"},
      {topics::RobotTrajectory().name, "iplan-trajopt"},
      {topics::TaskCommand().name, "iplan-supervisor"},
      {topics::TaskOutcome().name, "iplan-trajopt"},
      {topics::CollisionRisk().name, "iplan-collision_risk"},
      {topics::ActionBelief().name, "iplan-intent"},
      {topics::HumanPrediction().name, "iplan-intent"}};
  for (const auto& [topic, writer] : only_writer) {
    for (const auto& g : grants) EXPECT_EQ(Has(g.publish, topic), g.name == writer) << g.name << " on " << topic;
  }
  const auto& robot = Grant(grants, EnclaveName("robot_sim"));
  EXPECT_TRUE(Has(robot.subscribe, topics::SupervisorPermit().name));
  EXPECT_TRUE(Has(robot.subscribe, topics::CollisionRiskPermit().name));
  EXPECT_TRUE(Grant(grants, kObserverEnclave).publish.empty());
}

class CellKeystore : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("iplan-cell-keystore-" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(CellKeystore, IsMadeOnceThenLeftAlone) {
  const std::string ks = (dir_ / "a/b/keystore").string();  // parents made too
  const KeystoreReport first = EnsureCellKeystore(ks);
  EXPECT_TRUE(first.created);
  for (const auto& g : CellEnclaves()) {
    const dds::EnclaveGrant has = dds::ReadGrant(ks, g.name);
    EXPECT_EQ(has.publish, g.publish) << g.name;
    EXPECT_EQ(has.subscribe, g.subscribe) << g.name;
  }
  const auto ca_time = fs::last_write_time(ks + "/private/ca.key.pem");
  const KeystoreReport again = EnsureCellKeystore(ks);
  EXPECT_FALSE(again.created);
  EXPECT_TRUE(again.reissued.empty());
  EXPECT_EQ(fs::last_write_time(ks + "/private/ca.key.pem"), ca_time);
}

TEST_F(CellKeystore, AKilledCreationIsNeverTrustedAndIsCleanedUp) {
  const std::string ks = (dir_ / "keystore").string();
  // A creation killed before its rename leaves keystore.tmp.<its pid>, half
  // made (here: a CA and no enclaves); that process is gone.
  const pid_t dead = fork();
  if (dead == 0) _exit(0);
  waitpid(dead, nullptr, 0);
  const fs::path half = ks + ".tmp." + std::to_string(dead);
  fs::create_directories(half / "private");
  std::ofstream(half / "private/ca.key.pem") << "half";
  EXPECT_THROW(dds::LoadEnclave(ks, "iplan-supervisor"), std::runtime_error);  // no keystore at `ks`
  const KeystoreReport r = EnsureCellKeystore(ks);
  EXPECT_TRUE(r.created);
  EXPECT_FALSE(fs::exists(half)) << "the killed creation's folder is left";
  EXPECT_NO_THROW(dds::LoadEnclave(ks, "iplan-supervisor"));
}

TEST_F(CellKeystore, ReissuesInvalidOrOutdatedEnclavesWithItsOwnCa) {
  const std::string ks = (dir_ / "keystore").string();
  EnsureCellKeystore(ks);
  // Outdated: trajopt's grant of an older version (the shared permit topic).
  dds::CreateEnclave(ks, {"iplan-trajopt", {"rt/iplan/robot/trajectory"}, {"rt/iplan/safety/permit"}});
  // Invalid: perception's key readable by others; intent's enclave gone.
  fs::permissions(ks + "/enclaves/iplan-perception/key.pem", fs::perms::others_read, fs::perm_options::add);
  fs::remove_all(ks + "/enclaves/iplan-intent");
  const KeystoreReport r = EnsureCellKeystore(ks);
  EXPECT_FALSE(r.created);
  ASSERT_EQ(r.reissued.size(), 3u);
  std::string all;
  for (const auto& x : r.reissued) all += x + "\n";
  EXPECT_NE(all.find("iplan-trajopt: its permissions grant other topics than this version of the cell uses"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("iplan-perception: "), std::string::npos) << all;
  EXPECT_NE(all.find("iplan-intent: "), std::string::npos) << all;
  const std::string ca = Read(ks + "/public/ca.cert.pem");
  for (const char* name : {"iplan-trajopt", "iplan-perception", "iplan-intent"}) {
    ASSERT_NO_THROW(dds::LoadEnclave(ks, name)) << name;
    EXPECT_EQ(Read(dds::LoadEnclave(ks, name).identity_ca), ca) << name << " re-issued by another CA";
  }
  EXPECT_EQ(dds::ReadGrant(ks, "iplan-trajopt").subscribe,
            Grant(CellEnclaves(), "iplan-trajopt").subscribe);
  EXPECT_TRUE(EnsureCellKeystore(ks).reissued.empty());
}

TEST(UserKeystore, FollowsXdgDataHomeElseHome) {
  const char* xdg = std::getenv("XDG_DATA_HOME");
  const char* home = std::getenv("HOME");
  const std::string saved_xdg = xdg ? xdg : "", saved_home = home ? home : "";
  setenv("XDG_DATA_HOME", "/data", 1);
  EXPECT_EQ(UserKeystoreDir(), "/data/iplan/keystore");
  unsetenv("XDG_DATA_HOME");
  setenv("HOME", "/home/x", 1);
  EXPECT_EQ(UserKeystoreDir(), "/home/x/.local/share/iplan/keystore");
  unsetenv("HOME");
  EXPECT_THROW(UserKeystoreDir(), std::runtime_error);
  if (!saved_xdg.empty()) setenv("XDG_DATA_HOME", saved_xdg.c_str(), 1);
  if (!saved_home.empty()) setenv("HOME", saved_home.c_str(), 1);
}

}  // namespace
}  // namespace iplan::framework
