// File names of a DDS Security keystore (layout in iplan/dds/security.h).
// Internal to common/dds.
#pragma once

#include <string>

namespace iplan::dds::internal {

struct KeystorePaths {
  explicit KeystorePaths(const std::string& dir)
      : public_dir(dir + "/public"),
        private_dir(dir + "/private"),
        enclaves_dir(dir + "/enclaves"),
        ca_cert(public_dir + "/ca.cert.pem"),
        ca_key(private_dir + "/ca.key.pem"),
        governance_xml(enclaves_dir + "/governance.xml"),
        governance_p7s(enclaves_dir + "/governance.p7s") {}
  std::string public_dir, private_dir, enclaves_dir;
  std::string ca_cert, ca_key, governance_xml, governance_p7s;

  /// The files of the enclave in folder `d`.
  struct EnclavePaths {
    std::string identity_ca, certificate, private_key, permissions_ca, governance, permissions, permissions_xml;
  };
  static EnclavePaths Enclave(const std::string& d) {
    return {d + "/identity_ca.cert.pem", d + "/cert.pem",       d + "/key.pem",        d + "/permissions_ca.cert.pem",
            d + "/governance.p7s",       d + "/permissions.p7s", d + "/permissions.xml"};
  }
};

}  // namespace iplan::dds::internal
