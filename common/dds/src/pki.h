// The small part of OpenSSL that DDS Security keystores need: EC P-256 keys,
// X.509 certificates signed by a CA, and S/MIME signed documents (governance,
// permissions) as `openssl smime -sign -text` writes them and both vendors'
// access-control plugins read them. Internal to common/dds; no OpenSSL type
// leaves this header (PEM text in, PEM text out).
#pragma once

#include <string>

namespace iplan::dds::pki {

/// A private key and its certificate, PEM text.
struct KeyAndCertificate {
  std::string key_pem;   ///< PKCS#8 private key (keep secret: mode 0600)
  std::string cert_pem;  ///< X.509 certificate
};

/// A new self-signed CA (EC P-256, SHA-256), subject "CN=<common_name>",
/// valid from now for `days` days. Throws std::runtime_error with OpenSSL's
/// reason on failure. Allocates; thread-safe.
KeyAndCertificate CreateCa(const std::string& common_name, int days);

/// A new identity (EC P-256) with subject "CN=<common_name>", signed by
/// `ca` (SHA-256), valid from now for `days` days. Throws on failure.
KeyAndCertificate CreateIdentity(const std::string& common_name, const KeyAndCertificate& ca, int days);

/// `document` signed by `signer` as clear-signed S/MIME (detached PKCS#7,
/// text mode): the .p7s files of a DDS Security keystore. Throws on failure.
std::string SignSmime(const std::string& document, const KeyAndCertificate& signer);

/// Empty when `smime` is a valid signature by a certificate that `ca_pem`
/// issued (or is), else the reason. `content` receives the signed document.
std::string VerifySmime(const std::string& smime, const std::string& ca_pem, std::string* content);

/// Empty when `cert_pem` was issued by `ca_pem` and is valid now, and
/// `key_pem` is its private key; else the reason.
std::string VerifyIdentity(const std::string& cert_pem, const std::string& key_pem, const std::string& ca_pem);

/// The subject of a certificate in RFC 2253 form ("CN=iplan-trajopt").
/// Throws when `cert_pem` is not a certificate.
std::string SubjectOf(const std::string& cert_pem);

}  // namespace iplan::dds::pki
