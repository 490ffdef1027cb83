// DDS Security keystores for multi-process tests, made once per test program
// with `iplan security` (a keystore takes well under a second) in a folder of
// its own and removed at the end:
//  - Cell():  the cell's keystore, as `iplan demo` and the units use one;
//  - Other(): a second keystore with a CA of its own (an attacker's, or
//    another cell's);
//  - StolenObserver(): an attacker holding the cell's observer identity (its
//    certificate and private key, e.g. copied off a tools computer) under
//    permissions that grant publishing every catalogue topic, signed by
//    Other()'s CA, with Other()'s governance. It passes dds::LoadEnclave
//    (each document verifies against the CA it names), so the vendors' own
//    checks of the remote side are what keep it out.
// Register with ::testing::AddGlobalTestEnvironment(new TestKeystores).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "iplan/framework/enclaves.h"
#include "iplan/framework/topics.h"
#include "test_paths.h"

namespace iplan::testing {

class TestKeystores : public ::testing::Environment {
 public:
  static std::filesystem::path Dir() {
    return std::filesystem::temp_directory_path() / ("iplan-keys-" + std::to_string(getpid()));
  }
  static std::string Cell() { return (Dir() / "cell").string(); }
  static std::string Other() { return (Dir() / "other").string(); }
  static std::string StolenObserver() { return (Dir() / "stolen").string(); }

  void SetUp() override {
    namespace fs = std::filesystem;
    using namespace std::chrono_literals;
    fs::remove_all(Dir());
    fs::create_directories(Dir());
    for (const auto& d : {Cell(), Other()}) Run({"create-keystore", d});
    // The attacker's grant, made in its own keystore under the observer's
    // name (so its permissions name CN=iplan-observer) ...
    std::vector<std::string> grant = {"create-enclave", Other(), framework::kObserverEnclave};
    for (const auto& t : framework::topics::All()) grant.insert(grant.end(), {"--publish", t.name});
    Run(grant);
    // ... put together with the cell's observer identity.
    const fs::path cell = fs::path(Cell()) / "enclaves" / framework::kObserverEnclave;
    const fs::path other = fs::path(Other()) / "enclaves" / framework::kObserverEnclave;
    const fs::path stolen = fs::path(StolenObserver()) / "enclaves" / framework::kObserverEnclave;
    fs::create_directories(stolen);
    for (const char* f : {"cert.pem", "key.pem", "identity_ca.cert.pem"}) fs::copy_file(cell / f, stolen / f);
    for (const char* f : {"permissions_ca.cert.pem", "governance.p7s", "permissions.p7s", "permissions.xml"}) {
      fs::copy_file(other / f, stolen / f);
    }
    Run({"check", StolenObserver(), framework::kObserverEnclave});
  }
  void TearDown() override { std::filesystem::remove_all(Dir()); }

 private:
  static void Run(std::vector<std::string> args) {
    args.insert(args.begin(), {BinPath("iplan"), "security"});
    Process p(args);
    const auto rc = p.Wait(std::chrono::seconds(60));
    ASSERT_TRUE(rc && *rc == 0) << args[2] << ":\n" << p.Stdout() << p.Stderr();
  }
};

}  // namespace iplan::testing
