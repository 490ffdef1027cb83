// Using an enclave (iplan/dds/security.h): checking its files and the
// properties that turn on each vendor's builtin security plugins.
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "iplan/core/atomic_file.h"
#include "iplan/dds/security.h"
#include "keystore_layout.h"
#include "pki.h"

namespace iplan::dds {
namespace {

namespace fs = std::filesystem;

std::string Read(const std::string& path, const std::string& what) {
  try {
    return core::ReadFile(path);
  } catch (const std::exception&) {
    throw std::runtime_error(what + " " + path + " is missing or unreadable");
  }
}

// The private key must be the owner's alone (ssh's rule for keys).
void CheckKeyMode(const std::string& path) {
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error("private key " + path + " is missing");
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof(mode), "%04o", static_cast<unsigned>(st.st_mode & 07777));
    throw std::runtime_error("private key " + path + " has mode " + mode +
                             ": group or others may read it (chmod 600 it)");
  }
}

void CheckEnclave(const EnclaveFiles& f, const std::string& name) {
  const std::string identity_ca = Read(f.identity_ca, "identity CA");
  const std::string cert = Read(f.certificate, "identity certificate");
  CheckKeyMode(f.private_key);
  const std::string key = Read(f.private_key, "private key");
  if (std::string why = pki::VerifyIdentity(cert, key, identity_ca); !why.empty()) throw std::runtime_error(why);
  const std::string subject = pki::SubjectOf(cert);
  if (subject != "CN=" + name) {
    throw std::runtime_error("the identity certificate is for " + subject + ", not CN=" + name);
  }
  const std::string permissions_ca = Read(f.permissions_ca, "permissions CA");
  std::string content;
  if (std::string why = pki::VerifySmime(Read(f.governance, "governance"), permissions_ca, &content); !why.empty()) {
    throw std::runtime_error("governance " + f.governance + ": " + why);
  }
  if (std::string why = pki::VerifySmime(Read(f.permissions, "permissions"), permissions_ca, &content);
      !why.empty()) {
    throw std::runtime_error("permissions " + f.permissions + ": " + why);
  }
  if (content.find("<subject_name>" + subject + "</subject_name>") == std::string::npos) {
    throw std::runtime_error("permissions " + f.permissions + " grant nothing to " + subject);
  }
}

// "file://" + an absolute path: the form both vendors accept (Fast DDS
// refuses "file:/path").
std::string FileUri(const std::string& path) { return "file://" + path; }

}  // namespace

EnclaveFiles LoadEnclave(const std::string& dir, const std::string& name) {
  const std::string where = "security: enclave " + name + " in " + dir + ": ";
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) {
    throw std::runtime_error("security: keystore " + dir + " is not a folder (create one with `iplan security "
                             "create-keystore " + dir + "`)");
  }
  const internal::KeystorePaths ks(fs::absolute(dir, ec).lexically_normal().string());
  EnclaveFiles f;
  f.dir = ks.enclaves_dir + "/" + name;
  if (!fs::is_directory(f.dir, ec)) {
    throw std::runtime_error(where + "no folder " + f.dir + " (add it with `iplan security create-enclave " + dir +
                             " " + name + " ...`)");
  }
  const auto p = internal::KeystorePaths::Enclave(f.dir);
  f.identity_ca = p.identity_ca;
  f.certificate = p.certificate;
  f.private_key = p.private_key;
  f.permissions_ca = p.permissions_ca;
  f.governance = p.governance;
  f.permissions = p.permissions;
  try {
    CheckEnclave(f, name);
  } catch (const std::exception& e) {
    throw std::runtime_error(where + e.what());
  }
  return f;
}

namespace {

// The <topic> entries inside every <`rule`> ... </`rule`> of a permissions document.
std::vector<std::string> GrantedTopics(const std::string& doc, const std::string& rule) {
  std::vector<std::string> topics;
  const std::string open = "<" + rule + ">", close = "</" + rule + ">";
  for (auto at = doc.find(open); at != std::string::npos; at = doc.find(open, at + 1)) {
    const auto end = doc.find(close, at);
    if (end == std::string::npos) break;
    const std::string block = doc.substr(at, end - at);
    for (auto t = block.find("<topic>"); t != std::string::npos; t = block.find("<topic>", t + 1)) {
      const auto e = block.find("</topic>", t);
      if (e == std::string::npos) break;
      topics.push_back(block.substr(t + 7, e - t - 7));
    }
  }
  return topics;
}

}  // namespace

EnclaveGrant ReadGrant(const std::string& dir, const std::string& name) {
  const EnclaveFiles f = LoadEnclave(dir, name);
  std::string content;
  if (std::string why = pki::VerifySmime(core::ReadFile(f.permissions), core::ReadFile(f.permissions_ca), &content);
      !why.empty()) {
    throw std::runtime_error("security: enclave " + name + " in " + dir + ": permissions: " + why);
  }
  return {name, GrantedTopics(content, "publish"), GrantedTopics(content, "subscribe")};
}

std::string DefaultSecurityDir() {
  const char* v = std::getenv("IPLAN_SECURITY");
  return v && *v ? v : "";
}

Properties FastDdsSecurityProperties(const EnclaveFiles& f) {
  const std::string auth = "dds.sec.auth.builtin.PKI-DH.";
  const std::string access = "dds.sec.access.builtin.Access-Permissions.";
  return {
      {"dds.sec.auth.plugin", "builtin.PKI-DH"},
      {auth + "identity_ca", FileUri(f.identity_ca)},
      {auth + "identity_certificate", FileUri(f.certificate)},
      {auth + "private_key", FileUri(f.private_key)},
      {"dds.sec.access.plugin", "builtin.Access-Permissions"},
      {access + "permissions_ca", FileUri(f.permissions_ca)},
      {access + "governance", FileUri(f.governance)},
      {access + "permissions", FileUri(f.permissions)},
      {"dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC"},
  };
}

Properties CycloneSecurityProperties(const EnclaveFiles& f) {
  // Debian's libddsc finds the plugins by these names in
  // /usr/lib/<arch>/libddsc0debian/ (package libddsc0debian).
  return {
      {"dds.sec.auth.library.path", "dds_security_auth"},
      {"dds.sec.auth.library.init", "init_authentication"},
      {"dds.sec.auth.library.finalize", "finalize_authentication"},
      {"dds.sec.crypto.library.path", "dds_security_crypto"},
      {"dds.sec.crypto.library.init", "init_crypto"},
      {"dds.sec.crypto.library.finalize", "finalize_crypto"},
      {"dds.sec.access.library.path", "dds_security_ac"},
      {"dds.sec.access.library.init", "init_access_control"},
      {"dds.sec.access.library.finalize", "finalize_access_control"},
      {"dds.sec.auth.identity_ca", FileUri(f.identity_ca)},
      {"dds.sec.auth.identity_certificate", FileUri(f.certificate)},
      {"dds.sec.auth.private_key", FileUri(f.private_key)},
      {"dds.sec.access.permissions_ca", FileUri(f.permissions_ca)},
      {"dds.sec.access.governance", FileUri(f.governance)},
      {"dds.sec.access.permissions", FileUri(f.permissions)},
  };
}

}  // namespace iplan::dds
