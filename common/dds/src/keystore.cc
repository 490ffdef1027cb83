// Creating DDS Security keystores (iplan/dds/security.h): the CA, the signed
// governance and, per enclave, an identity and signed permissions.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "iplan/core/atomic_file.h"
#include "iplan/dds/security.h"
#include "keystore_layout.h"
#include "pki.h"

namespace iplan::dds {
namespace {

namespace fs = std::filesystem;
using internal::KeystorePaths;

[[noreturn]] void Fail(const std::string& dir, const std::string& why) {
  throw std::runtime_error("security: keystore " + dir + ": " + why);
}

void MakeDir(const std::string& path, unsigned mode) {
  if (::mkdir(path.c_str(), static_cast<mode_t>(mode)) != 0) {
    throw std::runtime_error("cannot create folder " + path + ": " + std::strerror(errno));
  }
  ::chmod(path.c_str(), static_cast<mode_t>(mode));  // exactly `mode`, whatever the umask
}

// The rename of a folder into `parent` survives a power loss.
void SyncFolder(const std::string& parent) {
  const int fd = ::open(parent.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void CheckOptions(const std::string& dir, const KeystoreOptions& o) {
  if (o.domain_min < 0 || o.domain_max > 230 || o.domain_min > o.domain_max) {
    Fail(dir, "domains [" + std::to_string(o.domain_min) + ", " + std::to_string(o.domain_max) +
                  "] are not a range within [0, 230] (Cyclone's access control refuses ids above 230)");
  }
  if (o.validity_days < 1 || o.validity_days > 36500) {
    Fail(dir, "validity of " + std::to_string(o.validity_days) + " days is not in [1, 36500]");
  }
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Domains(const KeystoreOptions& o, const char* indent) {
  std::ostringstream s;
  s << indent << "<domains>\n"
    << indent << "  <id_range><min>" << o.domain_min << "</min><max>" << o.domain_max << "</max></id_range>\n"
    << indent << "</domains>\n";
  return s.str();
}

// xs:dateTime in UTC, `offset_s` from now.
std::string DateTime(long long offset_s) {
  const std::time_t t = std::time(nullptr) + static_cast<std::time_t>(offset_s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

// One governance for the whole cell: nobody unauthenticated joins, discovery
// and liveliness encrypted, every message signed, every topic's data and
// metadata encrypted and its readers and writers checked against their
// permissions (the choices `ros2 security` makes).
std::string Governance(const KeystoreOptions& o) {
  std::ostringstream s;
  s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
       "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
       "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_governance.xsd\">\n"
       "  <domain_access_rules>\n"
       "    <domain_rule>\n"
    << Domains(o, "      ")
    << "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
       "      <enable_join_access_control>true</enable_join_access_control>\n"
       "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
       "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
       "      <rtps_protection_kind>SIGN</rtps_protection_kind>\n"
       "      <topic_access_rules>\n"
       "        <topic_rule>\n"
       "          <topic_expression>*</topic_expression>\n"
       "          <enable_discovery_protection>true</enable_discovery_protection>\n"
       "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
       "          <enable_read_access_control>true</enable_read_access_control>\n"
       "          <enable_write_access_control>true</enable_write_access_control>\n"
       "          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>\n"
       "          <data_protection_kind>ENCRYPT</data_protection_kind>\n"
       "        </topic_rule>\n"
       "      </topic_access_rules>\n"
       "    </domain_rule>\n"
       "  </domain_access_rules>\n"
       "</dds>\n";
  return s.str();
}

void Topics(std::ostringstream& s, const char* what, const std::vector<std::string>& topics) {
  if (topics.empty()) return;
  s << "        <" << what << ">\n          <topics>\n";
  for (const auto& t : topics) s << "            <topic>" << XmlEscape(t) << "</topic>\n";
  s << "          </topics>\n        </" << what << ">\n";
}

// The grant of one enclave: exactly its topics, everything else denied.
std::string Permissions(const EnclaveGrant& g, const std::string& subject, const KeystoreOptions& o) {
  std::ostringstream s;
  s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
       "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
       "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_permissions.xsd\">\n"
       "  <permissions>\n"
    << "    <grant name=\"" << XmlEscape(g.name) << "\">\n"
    << "      <subject_name>" << XmlEscape(subject) << "</subject_name>\n"
    << "      <validity>\n        <not_before>" << DateTime(-86400) << "</not_before>\n"
    << "        <not_after>" << DateTime(static_cast<long long>(o.validity_days) * 86400) << "</not_after>\n"
    << "      </validity>\n"
    << "      <allow_rule>\n"
    << Domains(o, "        ");
  Topics(s, "publish", g.publish);
  Topics(s, "subscribe", g.subscribe);
  s << "      </allow_rule>\n"
       "      <default>DENY</default>\n"
       "    </grant>\n"
       "  </permissions>\n"
       "</dds>\n";
  return s.str();
}

void CheckName(const std::string& dir, const std::string& name) {
  bool ok = !name.empty() && name.size() <= 64 && name[0] != '.';
  for (char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.');
  if (!ok) Fail(dir, "enclave name '" + name + "' is not 1-64 characters of [A-Za-z0-9_.-] (not starting with '.')");
}

// Writes enclave `g` into `enclave_dir` (a new folder).
void WriteEnclave(const KeystorePaths& ks, const std::string& enclave_dir, const EnclaveGrant& g,
                  const pki::KeyAndCertificate& ca, const KeystoreOptions& o) {
  MakeDir(enclave_dir, 0750);
  const pki::KeyAndCertificate id = pki::CreateIdentity(g.name, ca, o.validity_days);
  const auto p = KeystorePaths::Enclave(enclave_dir);
  core::WriteFileAtomically(p.private_key, id.key_pem, 0600);
  core::WriteFileAtomically(p.certificate, id.cert_pem);
  core::WriteFileAtomically(p.identity_ca, ca.cert_pem);
  core::WriteFileAtomically(p.permissions_ca, ca.cert_pem);
  core::WriteFileAtomically(p.governance, core::ReadFile(ks.governance_p7s));
  const std::string permissions = Permissions(g, pki::SubjectOf(id.cert_pem), o);
  core::WriteFileAtomically(p.permissions_xml, permissions);
  core::WriteFileAtomically(p.permissions, pki::SignSmime(permissions, ca));
}

}  // namespace

void CreateKeystore(const std::string& dir_text, const std::vector<EnclaveGrant>& grants,
                    const KeystoreOptions& options) {
  // "a/ks/" and "a/ks" are one keystore; its temporary goes beside it.
  std::string dir = dir_text;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  CheckOptions(dir, options);
  for (const auto& g : grants) CheckName(dir, g.name);
  std::error_code ec;
  const bool existed = fs::exists(dir, ec);
  if (existed && !fs::is_directory(dir, ec)) Fail(dir, "exists and is not a folder");
  if (existed && !fs::is_empty(dir, ec)) {
    Fail(dir, "exists and is not empty (an existing keystore is never overwritten; add an enclave with "
              "`iplan security create-enclave`, or remove the folder first)");
  }
  const fs::path parent = fs::absolute(dir, ec).parent_path();
  fs::create_directories(parent, ec);
  // Built beside the target and renamed into place: the keystore appears
  // whole or not at all. A creation killed before its rename left only its
  // temporary folder: removed here, never used.
  core::RemoveStaleTempFiles(dir);
  const std::string tmp = dir + ".tmp." + std::to_string(::getpid());
  fs::remove_all(tmp, ec);
  try {
    MakeDir(tmp, 0755);
    const KeystorePaths ks(tmp);
    MakeDir(ks.public_dir, 0755);
    MakeDir(ks.private_dir, 0700);
    MakeDir(ks.enclaves_dir, 0755);
    const pki::KeyAndCertificate ca = pki::CreateCa("iplan keystore CA", options.validity_days);
    core::WriteFileAtomically(ks.ca_key, ca.key_pem, 0600);
    core::WriteFileAtomically(ks.ca_cert, ca.cert_pem);
    const std::string governance = Governance(options);
    core::WriteFileAtomically(ks.governance_xml, governance);
    core::WriteFileAtomically(ks.governance_p7s, pki::SignSmime(governance, ca));
    for (const auto& g : grants) WriteEnclave(ks, ks.enclaves_dir + "/" + g.name, g, ca, options);
    // rename(2) replaces an empty folder and refuses a non-empty one (a
    // keystore another process made meanwhile): never a mix of two.
    fs::rename(tmp, dir);
    SyncFolder(parent.string());
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    Fail(dir, e.what());
  }
}

void CreateEnclave(const std::string& dir, const EnclaveGrant& grant, const KeystoreOptions& options) {
  CheckOptions(dir, options);
  CheckName(dir, grant.name);
  const KeystorePaths ks(dir);
  pki::KeyAndCertificate ca;
  try {
    ca = {core::ReadFile(ks.ca_key), core::ReadFile(ks.ca_cert)};
    core::ReadFile(ks.governance_p7s);
  } catch (const std::exception& e) {
    Fail(dir, std::string("not a keystore (create one with `iplan security create-keystore`): ") + e.what());
  }
  const std::string target = ks.enclaves_dir + "/" + grant.name;
  const std::string tmp = target + ".tmp." + std::to_string(::getpid());
  const std::string old = target + ".old." + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(tmp, ec);
  try {
    WriteEnclave(ks, tmp, grant, ca, options);
    if (fs::exists(target)) fs::rename(target, old);
    fs::rename(tmp, target);
    fs::remove_all(old, ec);
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    Fail(dir, "enclave " + grant.name + ": " + e.what());
  }
}

}  // namespace iplan::dds
