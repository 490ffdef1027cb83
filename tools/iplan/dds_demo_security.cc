#include "dds_demo_security.h"

#include <iostream>
#include <stdexcept>

#include "iplan/dds/security.h"
#include "iplan/framework/enclaves.h"

namespace iplan::cli {

DemoSecurity SecureDemo(bool insecure, const std::string& keystore, bool mixed) {
  DemoSecurity s;
  if (insecure) {
    if (!keystore.empty()) throw std::runtime_error("--insecure contradicts --security " + keystore);
    s.summary = "no DDS Security (--insecure): any process on the network could read and command this cell";
    s.service_args = {"--insecure"};
    s.env = {{"IPLAN_SECURITY", ""}};
    return s;
  }
  if (mixed) {
    throw std::runtime_error(
        "--mixed runs secured only where both DDS vendors can authenticate each other, and Debian's Fast DDS "
        "2.9 and Cyclone DDS 0.10 cannot: Cyclone fails to read the Diffie-Hellman public key in a Fast DDS "
        "handshake request (\"Failed to convert octet sequence to ASN1 integer\"), so every pair of "
        "participants in which the Fast DDS one begins the handshake never matches, and no split of the "
        "cell's services avoids such pairs reliably (docs/dds.md, \"Mixed vendors: what fails\"). Run "
        "`iplan demo --mixed --insecure` to see both vendors together, or `iplan demo` (one vendor, secured)");
  }
  s.secured = true;
  s.keystore = !keystore.empty() ? keystore : dds::DefaultSecurityDir();
  std::string how = keystore.empty() && !s.keystore.empty() ? "$IPLAN_SECURITY" : "--security";
  if (s.keystore.empty()) {
    s.keystore = framework::UserKeystoreDir();
    const framework::KeystoreReport r = framework::EnsureCellKeystore(s.keystore);
    how = r.created ? "this user's, created now"
                    : r.reissued.empty() ? "this user's"
                                         : "this user's, " + std::to_string(r.reissued.size()) + " enclaves re-issued";
  }
  s.summary = "DDS Security: authenticated, encrypted, each service granted its own topics (keystore " + s.keystore +
              ", " + how + ")";
  s.service_args = {"--security", s.keystore};
  s.env = {{"IPLAN_SECURITY", s.keystore}};
  return s;
}

dds::ParticipantOptions DemoSecurity::Participant(dds::Vendor vendor, int domain, const std::string& name) const {
  dds::ParticipantOptions p;
  p.vendor = vendor;
  p.domain_id = domain;
  p.name = secured ? framework::kObserverEnclave : name;
  p.security_dir = secured ? keystore : "";
  return p;
}

void AddDemoSecurityOptions(CLI::App* demo, bool* insecure, std::string* keystore) {
  demo->add_flag("--insecure", *insecure,
                 "run the cell without DDS Security (default: secured, each service authenticated as its enclave "
                 "and granted only its own topics)");
  demo->add_option("--security", *keystore,
                   "DDS Security keystore to run with (default: $IPLAN_SECURITY, else this user's keystore, "
                   "$XDG_DATA_HOME/iplan/keystore or ~/.local/share/iplan/keystore, made on first use)");
}

std::optional<DemoSecurity> SecureDemoOrExplain(bool insecure, const std::string& keystore, bool mixed, int domain,
                                                const std::string& view_args) {
  try {
    DemoSecurity s = SecureDemo(insecure, keystore, mixed);
    std::cout << "  " << s.summary << "\n  watch it: iplan view --domain " << domain
              << (s.secured ? " --security " + s.keystore : std::string()) << view_args << "\n";
    return s;
  } catch (const std::exception& e) {
    std::cerr << "iplan demo: refused: " << e.what() << "\n";
    return std::nullopt;
  }
}

}  // namespace iplan::cli
