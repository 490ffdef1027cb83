// Keystores and enclave checks without DDS (iplan/dds/security.h): what
// CreateKeystore refuses, and each way LoadEnclave finds an enclave invalid.
#include "iplan/dds/security.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "iplan/core/atomic_file.h"

namespace iplan::dds {
namespace {

namespace fs = std::filesystem;

const std::vector<EnclaveGrant> kGrants = {
    {"iplan-a", {"rt/x"}, {"rt/y"}},
    {"iplan-b", {"rt/y"}, {}},
};

// The message of what `f` throws ("" when it does not).
template <class F>
std::string Thrown(F f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

class Security : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("iplan-security-unit-" + std::to_string(getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    CreateKeystore(Dir("ks"), kGrants);
  }
  void TearDown() override { fs::remove_all(root_); }
  std::string Dir(const std::string& name) const { return (root_ / name).string(); }
  fs::path root_;
};

TEST_F(Security, AValidEnclaveGivesBothVendorsAbsoluteFileUris) {
  const EnclaveFiles f = LoadEnclave(Dir("ks"), "iplan-a");
  EXPECT_EQ(f.dir, Dir("ks") + "/enclaves/iplan-a");
  const Properties fast = FastDdsSecurityProperties(f);
  const Properties cyclone = CycloneSecurityProperties(f);
  ASSERT_EQ(fast.size(), 9u);
  ASSERT_EQ(cyclone.size(), 15u);
  for (const auto& props : {fast, cyclone}) {
    int files = 0;
    for (const auto& [name, value] : props) {
      if (value.rfind("file://", 0) != 0) continue;
      ++files;
      EXPECT_TRUE(fs::is_regular_file(value.substr(7))) << name << " = " << value;
      EXPECT_EQ(value[7], '/') << value;
    }
    EXPECT_EQ(files, 6);
  }
  const std::string xml = core::ReadFile(Dir("ks") + "/enclaves/iplan-a/permissions.xml");
  EXPECT_NE(xml.find("<publish>\n          <topics>\n            <topic>rt/x</topic>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<subscribe>\n          <topics>\n            <topic>rt/y</topic>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<id_range><min>0</min><max>230</max></id_range>"), std::string::npos);
  // b subscribes to nothing: no empty <subscribe> element.
  EXPECT_EQ(core::ReadFile(Dir("ks") + "/enclaves/iplan-b/permissions.xml").find("<subscribe>"), std::string::npos);
}

TEST_F(Security, CreateKeystoreRefusesBadTargetsAndOptions) {
  std::ofstream(Dir("file")) << "x";
  EXPECT_NE(Thrown([&] { CreateKeystore(Dir("file"), kGrants); }).find("exists and is not a folder"), std::string::npos);
  EXPECT_NE(Thrown([&] { CreateKeystore(Dir("ks"), kGrants); }).find("exists and is not empty"), std::string::npos);
  EXPECT_NE(Thrown([&] { CreateKeystore(Dir("bad"), {{"../x", {}, {}}}); }).find("enclave name '../x'"),
            std::string::npos);
  KeystoreOptions o;
  o.domain_max = 231;
  EXPECT_NE(Thrown([&] { CreateKeystore(Dir("bad"), kGrants, o); }).find("within [0, 230]"), std::string::npos);
  EXPECT_FALSE(fs::exists(Dir("bad")));
  // An empty folder is fine, and no temporary is left beside it.
  fs::create_directories(Dir("empty"));
  EXPECT_EQ(Thrown([&] { CreateKeystore(Dir("empty"), kGrants); }), "");
  for (const auto& e : fs::directory_iterator(root_)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  }
  EXPECT_NE(Thrown([&] { CreateEnclave(Dir("nothing"), kGrants[0]); }).find("not a keystore"), std::string::npos);
}

TEST_F(Security, LoadEnclaveNamesWhatIsWrong) {
  CreateKeystore(Dir("other"), kGrants);
  const std::string a = Dir("ks") + "/enclaves/iplan-a";
  const std::string b = Dir("ks") + "/enclaves/iplan-b";
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-c"); }).find("no folder"), std::string::npos);
  // Another CA's certificate and key in our enclave.
  fs::copy_file(Dir("other") + "/enclaves/iplan-a/cert.pem", a + "/cert.pem", fs::copy_options::overwrite_existing);
  fs::copy_file(Dir("other") + "/enclaves/iplan-a/key.pem", a + "/key.pem", fs::copy_options::overwrite_existing);
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }).find("does not verify against the identity CA"),
            std::string::npos);
  // Our certificate with another key.
  fs::copy_file(b + "/cert.pem", a + "/cert.pem", fs::copy_options::overwrite_existing);
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }).find("does not belong"), std::string::npos);
  // b's identity under a's name.
  fs::copy_file(b + "/key.pem", a + "/key.pem", fs::copy_options::overwrite_existing);
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }).find("is for CN=iplan-b, not CN=iplan-a"),
            std::string::npos);
  // b's valid, signed permissions in a's enclave grant a nothing.
  CreateEnclave(Dir("ks"), kGrants[0]);  // a repaired
  EXPECT_EQ(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }), "");
  fs::copy_file(b + "/permissions.p7s", a + "/permissions.p7s", fs::copy_options::overwrite_existing);
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }).find("grant nothing to CN=iplan-a"),
            std::string::npos);
  // Governance signed by another CA.
  CreateEnclave(Dir("ks"), kGrants[0]);
  fs::copy_file(Dir("other") + "/enclaves/governance.p7s", a + "/governance.p7s", fs::copy_options::overwrite_existing);
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }).find("governance"), std::string::npos);
  // A key others may read; a missing file.
  CreateEnclave(Dir("ks"), kGrants[0]);
  fs::permissions(a + "/key.pem", fs::perms::group_read, fs::perm_options::add);
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-a"); }).find("has mode 0640"), std::string::npos);
  fs::remove(b + "/identity_ca.cert.pem");
  EXPECT_NE(Thrown([&] { LoadEnclave(Dir("ks"), "iplan-b"); }).find("identity CA"), std::string::npos);
}

}  // namespace
}  // namespace iplan::dds
