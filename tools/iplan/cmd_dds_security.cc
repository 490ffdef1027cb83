// `iplan security`: DDS Security keystores the way `ros2 security` makes
// them (a CA, a signed governance, one enclave per service with exactly its
// topics), adding enclaves, and checking them (docs/dds.md, "DDS Security").
#include <iostream>
#include <string>
#include <vector>

#include "command_registry.h"
#include "dds_common.h"
#include "iplan/dds/security.h"
#include "iplan/framework/enclaves.h"

namespace {

using iplan::cli::SetExitCode;

struct Options {
  std::string dir;
  std::string name;
  int domain = -1;
  int days = 3650;
  std::vector<std::string> publish, subscribe;
};

iplan::dds::KeystoreOptions KeystoreOptionsFrom(const Options& o) {
  iplan::dds::KeystoreOptions k;
  if (o.domain >= 0) k.domain_min = k.domain_max = o.domain;
  k.validity_days = o.days;
  return k;
}

void CreateKeystore(const Options& o) {
  const auto grants = iplan::framework::CellEnclaves();
  iplan::dds::CreateKeystore(o.dir, grants, KeystoreOptionsFrom(o));
  std::cout << "keystore " << o.dir << ": CA, governance and " << grants.size() << " enclaves:";
  for (const auto& g : grants) std::cout << " " << g.name;
  std::cout << "\nstart the services with --security " << o.dir << " (or IPLAN_SECURITY=" << o.dir << ")\n";
}

// The keystore a cell of this version runs with, made or brought up to date.
void EnsureKeystore(const Options& o) {
  const std::string dir = o.dir.empty() ? iplan::framework::UserKeystoreDir() : o.dir;
  const iplan::framework::KeystoreReport r = iplan::framework::EnsureCellKeystore(dir);
  if (r.created) {
    std::cout << "keystore " << dir << ": created (CA, governance, " << iplan::framework::CellEnclaves().size()
              << " enclaves)\n";
  } else if (r.reissued.empty()) {
    std::cout << "keystore " << dir << ": present; every enclave of the cell valid and current\n";
  } else {
    std::cout << "keystore " << dir << ": re-issued " << r.reissued.size() << " enclaves (signed by its CA):\n";
    for (const auto& why : r.reissued) std::cout << "  " << why << "\n";
  }
}

void CreateEnclave(const Options& o) {
  iplan::dds::EnclaveGrant g{o.name, {}, {}};
  for (const auto& t : o.publish) g.publish.push_back(iplan::cli::DdsTopicName(t));
  for (const auto& t : o.subscribe) g.subscribe.push_back(iplan::cli::DdsTopicName(t));
  iplan::dds::CreateEnclave(o.dir, g, KeystoreOptionsFrom(o));
  std::cout << "enclave " << o.name << " in " << o.dir << ": publishes " << g.publish.size() << ", subscribes "
            << g.subscribe.size() << " topics\n";
}

// Every enclave of the cell (or the one named): 0 when all are valid.
int Check(const Options& o) {
  std::vector<std::string> names;
  if (!o.name.empty()) {
    names.push_back(o.name);
  } else {
    for (const auto& g : iplan::framework::CellEnclaves()) names.push_back(g.name);
  }
  int bad = 0;
  for (const auto& n : names) {
    try {
      const auto f = iplan::dds::LoadEnclave(o.dir, n);
      std::cout << n << ": valid (" << f.dir << ")\n";
    } catch (const std::exception& e) {
      std::cout << e.what() << "\n";
      ++bad;
    }
  }
  return bad == 0 ? 0 : 1;
}

template <class F>
void Run(F f) {
  try {
    f();
  } catch (const std::exception& e) {
    std::cerr << "iplan security: " << e.what() << "\n";
    SetExitCode(1);
  }
}

const bool kRegistered = iplan::cli::RegisterCommand("security", [](CLI::App& app) {
  auto* sec = app.add_subcommand("security", "DDS Security keystores and enclaves (like `ros2 security`)");
  sec->require_subcommand(1);
  static Options o;
  auto* ks = sec->add_subcommand(
      "create-keystore",
      "Create a keystore: one CA (identity and permissions), a signed governance (authentication required, "
      "discovery and data encrypted, access control on every topic) and one enclave per iplan service and "
      "iplan-observer, each granted exactly its topics. DIR must not exist or be empty.");
  ks->add_option("dir", o.dir, "keystore folder to create")->required();
  ks->add_option("--domain", o.domain, "the one DDS domain the keystore covers (default: all, 0-230)")
      ->check(CLI::Range(0, 230));
  ks->add_option("--days", o.days, "validity of certificates and permissions in days")
      ->check(CLI::Range(1, 36500))
      ->capture_default_str();
  ks->callback([] { Run([] { CreateKeystore(o); }); });

  auto* ek = sec->add_subcommand(
      "ensure-keystore",
      "Make DIR a keystore this version of the cell runs with: create it when missing (built beside it and "
      "renamed into place: never half made), re-issue any cell enclave that is invalid or grants other topics "
      "than the cell now uses (signed by its own CA), leave all else alone. `iplan demo` does this on first use "
      "and scripts/setup.sh runs it.");
  ek->add_option("dir", o.dir,
                 "keystore folder (default: this user's, $XDG_DATA_HOME/iplan/keystore or "
                 "~/.local/share/iplan/keystore)");
  ek->callback([] { Run([] { EnsureKeystore(o); }); });

  auto* en = sec->add_subcommand(
      "create-enclave",
      "Add or replace an enclave of an existing keystore (e.g. a robot bridge of your own), signed by its CA");
  en->add_option("dir", o.dir, "keystore folder")->required();
  en->add_option("name", o.name, "enclave name = participant name, e.g. iplan-robot-bridge")->required();
  en->add_option("--publish", o.publish, "topic it may publish, e.g. /joint_states (repeatable)");
  en->add_option("--subscribe", o.subscribe, "topic it may subscribe to, e.g. /iplan/safety/permit/supervisor (repeatable)");
  en->add_option("--domain", o.domain, "the one DDS domain it covers (default: all, 0-230)")
      ->check(CLI::Range(0, 230));
  en->add_option("--days", o.days, "validity in days")->check(CLI::Range(1, 36500))->capture_default_str();
  en->callback([] { Run([] { CreateEnclave(o); }); });

  auto* ck = sec->add_subcommand("check",
                                 "Check enclaves as a service would before starting: files, key mode, "
                                 "certificate chain and validity, signatures. Exit 0 when all are valid.");
  ck->add_option("dir", o.dir, "keystore folder")->required();
  ck->add_option("name", o.name, "one enclave (default: every enclave of the cell)");
  ck->callback([] { SetExitCode(Check(o)); });
});

}  // namespace
