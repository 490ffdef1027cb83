// DDS Security (OMG DDS Security 1.1 builtin plugins: PKI-DH authentication,
// signed permissions access control, AES-GCM-GMAC encryption) for iplan
// participants, with a keystore laid out the way `ros2 security` lays it out:
//
//   DIR/public/ca.cert.pem              the CA (identity CA = permissions CA)
//   DIR/private/ca.key.pem              its key (0600, folder 0700)
//   DIR/enclaves/governance.xml, .p7s   one governance for the cell, signed
//   DIR/enclaves/<name>/                one enclave per participant name:
//     identity_ca.cert.pem, permissions_ca.cert.pem, cert.pem, key.pem (0600),
//     governance.p7s, permissions.xml, permissions.p7s (signed)
//
// Both vendors' plugins read these files (Fast DDS dds.sec.* properties,
// Cyclone DDS dds.sec.* QoS properties); see docs/dds.md, "DDS Security".
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace iplan::dds {

/// What one enclave may do: DDS topic names ("rt/iplan/robot/trajectory")
/// it may publish and subscribe; everything else is denied.
struct EnclaveGrant {
  std::string name;  ///< the participant name, e.g. "iplan-trajopt"; CN of its certificate
  std::vector<std::string> publish;
  std::vector<std::string> subscribe;
};

struct KeystoreOptions {
  /// Domains the governance and permissions cover, within [0, 230]: Cyclone's
  /// access control refuses domain ids above 230 in these documents.
  int domain_min = 0;
  int domain_max = 230;
  int validity_days = 3650;  ///< certificates and permissions, from now
};

/// Creates a new keystore in `dir` (which must not exist, or be an empty
/// folder) with a CA, the governance document and one enclave per grant.
/// Every file is written atomically; keys with mode 0600 in folders the
/// owner alone can enter. Throws std::runtime_error naming the path and the
/// reason (existing keystore, not a folder, cannot write, OpenSSL failure).
/// The keystore is built in `dir`.tmp.<pid> and renamed into place, so `dir`
/// appears whole or not at all, also when the process is killed; such a
/// killed creation's folder is removed by the next creation. Allocates.
void CreateKeystore(const std::string& dir, const std::vector<EnclaveGrant>& grants,
                    const KeystoreOptions& options = {});

/// Adds (or replaces) one enclave of an existing keystore, signed by its CA.
/// Throws std::runtime_error when `dir` is not a keystore or on failure.
void CreateEnclave(const std::string& dir, const EnclaveGrant& grant, const KeystoreOptions& options = {});

/// The files of one enclave, checked.
struct EnclaveFiles {
  std::string dir;  ///< DIR/enclaves/<name>
  std::string identity_ca, certificate, private_key;
  std::string permissions_ca, governance, permissions;
};

/// The enclave `name` of keystore `dir`, checked the way the vendors will
/// check it, to fail early with a clear reason: every file present and
/// readable, the private key not readable by group or others, the
/// certificate issued by the identity CA, valid now and matching the key,
/// governance and permissions signed by the permissions CA, and the
/// permissions naming the certificate's subject. Throws std::runtime_error
/// ("security: enclave iplan-trajopt in /etc/iplan/keystore: ...").
EnclaveFiles LoadEnclave(const std::string& dir, const std::string& name);

/// What the enclave `name` of keystore `dir` is granted: the topics of the
/// publish and subscribe rules of its signed permissions (after LoadEnclave's
/// checks), in document order. Throws std::runtime_error like LoadEnclave.
/// Allocates.
EnclaveGrant ReadGrant(const std::string& dir, const std::string& name);

/// IPLAN_SECURITY from the environment (a keystore folder), else "".
std::string DefaultSecurityDir();

/// Name/value properties that turn on the builtin plugins with `files`:
/// Fast DDS 2.9 (dds.sec.auth.plugin = builtin.PKI-DH, ...) and Cyclone DDS
/// 0.10 (dds.sec.auth.library.path = dds_security_auth, ...).
using Properties = std::vector<std::pair<std::string, std::string>>;
Properties FastDdsSecurityProperties(const EnclaveFiles& files);
Properties CycloneSecurityProperties(const EnclaveFiles& files);

}  // namespace iplan::dds
