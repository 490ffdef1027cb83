// How `iplan demo` secures its cell: DDS Security by default, with this
// user's keystore (framework::UserKeystoreDir()) made on first use, or the
// keystore given (--security, $IPLAN_SECURITY); --insecure opts out. A
// secured cell split over both vendors (--mixed) is refused with the
// reason: Debian's Fast DDS 2.9 and Cyclone DDS 0.10 cannot complete the
// handshake between some pairs of participants (docs/dds.md, "Mixed
// vendors: what fails").
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "iplan/dds/participant.h"

namespace iplan::cli {

struct DemoSecurity {
  bool secured = false;
  std::string keystore;  ///< the keystore folder when secured
  std::string summary;   ///< one line: "DDS Security: ... (keystore ...)" or "no DDS Security (--insecure) ..."
  /// What every service of the cell gets on its command line:
  /// {"--security", keystore} or {"--insecure"}.
  std::vector<std::string> service_args;
  /// The environment every process of the cell gets (services, recorder):
  /// IPLAN_SECURITY set to the keystore, or emptied for --insecure (so an
  /// inherited one cannot contradict it).
  std::map<std::string, std::string> env;

  /// The demo's own participant: with security the observer's enclave
  /// (reads every topic, writes none), else named `name`.
  dds::ParticipantOptions Participant(dds::Vendor vendor, int domain, const std::string& name) const;
};

/// Adds --insecure and --security DIR to the demo's command line.
void AddDemoSecurityOptions(CLI::App* demo, bool* insecure, std::string* keystore);

/// Decides the demo's security: `insecure` (--insecure), else the keystore
/// `keystore` (--security), else $IPLAN_SECURITY (both used as they are and
/// checked by the services), else this user's keystore, created or brought
/// up to date (framework::EnsureCellKeystore). Throws std::runtime_error
/// with the reason to refuse: --mixed secured, --insecure with --security,
/// a keystore that cannot be made. Allocates; may write the keystore.
DemoSecurity SecureDemo(bool insecure, const std::string& keystore, bool mixed);

/// SecureDemo, its summary and how to watch the cell on `domain` (the
/// `iplan view` command line, `view_args` appended, e.g. " --robot FILE")
/// printed as lines of the demo's header; nullopt
/// (the reason printed on stderr) when the demo must not run.
std::optional<DemoSecurity> SecureDemoOrExplain(bool insecure, const std::string& keystore, bool mixed, int domain,
                                                const std::string& view_args = "");

}  // namespace iplan::cli
