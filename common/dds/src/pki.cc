#include "pki.h"

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <memory>
#include <stdexcept>

namespace iplan::dds::pki {
namespace {

template <class T, void (*F)(T*)>
struct Free {
  void operator()(T* p) const { F(p); }
};
using Bio = std::unique_ptr<BIO, Free<BIO, BIO_free_all>>;
using Key = std::unique_ptr<EVP_PKEY, Free<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Free<X509, X509_free>>;
using P7 = std::unique_ptr<PKCS7, Free<PKCS7, PKCS7_free>>;
using Store = std::unique_ptr<X509_STORE, Free<X509_STORE, X509_STORE_free>>;
using StoreCtx = std::unique_ptr<X509_STORE_CTX, Free<X509_STORE_CTX, X509_STORE_CTX_free>>;
using Bignum = std::unique_ptr<BIGNUM, Free<BIGNUM, BN_free>>;

// Certificates start an hour in the past, so hosts whose clocks differ a
// little still accept each other's.
constexpr long kBackdate = 3600;

// OpenSSL's reason for the last failure (and clears its error queue).
std::string Reason(const std::string& what) {
  const unsigned long e = ERR_get_error();
  ERR_clear_error();
  if (e == 0) return what;
  char buf[256];
  ERR_error_string_n(e, buf, sizeof(buf));
  return what + " (" + buf + ")";
}

[[noreturn]] void Fail(const std::string& what) { throw std::runtime_error("OpenSSL: " + Reason(what)); }

Bio ReadBio(const std::string& s) {
  Bio b(BIO_new_mem_buf(s.data(), static_cast<int>(s.size())));
  if (!b) Fail("cannot allocate a buffer");
  return b;
}

Bio WriteBio() {
  Bio b(BIO_new(BIO_s_mem()));
  if (!b) Fail("cannot allocate a buffer");
  return b;
}

std::string Text(BIO* b) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(b, &data);
  return n > 0 ? std::string(data, static_cast<std::size_t>(n)) : std::string();
}

Key ReadKey(const std::string& pem) {
  Bio b = ReadBio(pem);
  return Key(PEM_read_bio_PrivateKey(b.get(), nullptr, nullptr, nullptr));
}

Cert ReadCert(const std::string& pem) {
  Bio b = ReadBio(pem);
  return Cert(PEM_read_bio_X509(b.get(), nullptr, nullptr, nullptr));
}

std::string KeyPem(EVP_PKEY* key) {
  Bio b = WriteBio();
  if (PEM_write_bio_PrivateKey(b.get(), key, nullptr, nullptr, 0, nullptr, nullptr) != 1) Fail("cannot write a key");
  return Text(b.get());
}

std::string CertPem(X509* cert) {
  Bio b = WriteBio();
  if (PEM_write_bio_X509(b.get(), cert) != 1) Fail("cannot write a certificate");
  return Text(b.get());
}

Key NewKey() {
  Key k(EVP_PKEY_Q_keygen(nullptr, nullptr, "EC", "P-256"));
  if (!k) Fail("cannot generate an EC P-256 key");
  return k;
}

void AddExtension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (!ext) Fail(std::string("cannot make extension ") + value);
  const int ok = X509_add_ext(cert, ext, -1);
  X509_EXTENSION_free(ext);
  if (ok != 1) Fail(std::string("cannot add extension ") + value);
}

// A certificate for `subject_key` named CN=<cn>; self-signed when `issuer`
// is null. Like `ros2 security`: basic constraints only (no key usage), so
// the CA may sign the governance and permissions documents itself.
Cert MakeCertificate(const std::string& cn, EVP_PKEY* subject_key, X509* issuer, EVP_PKEY* issuer_key,
                     bool ca, int days) {
  Cert c(X509_new());
  if (!c) Fail("cannot allocate a certificate");
  X509_set_version(c.get(), 2);
  Bignum serial(BN_new());
  if (!serial || BN_rand(serial.get(), 63, BN_RAND_TOP_ANY, BN_RAND_BOTTOM_ANY) != 1 ||
      !BN_to_ASN1_INTEGER(serial.get(), X509_get_serialNumber(c.get()))) {
    Fail("cannot make a serial number");
  }
  X509_gmtime_adj(X509_getm_notBefore(c.get()), -kBackdate);
  X509_gmtime_adj(X509_getm_notAfter(c.get()), static_cast<long>(days) * 86400);
  if (X509_set_pubkey(c.get(), subject_key) != 1) Fail("cannot set the public key");
  X509_NAME* name = X509_get_subject_name(c.get());
  if (X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(cn.c_str()), -1,
                                 -1, 0) != 1) {
    Fail("cannot set the subject CN=" + cn);
  }
  X509* signer = issuer ? issuer : c.get();
  X509_set_issuer_name(c.get(), X509_get_subject_name(signer));
  AddExtension(c.get(), signer, NID_basic_constraints, ca ? "critical,CA:TRUE,pathlen:1" : "critical,CA:FALSE");
  AddExtension(c.get(), signer, NID_subject_key_identifier, "hash");
  if (X509_sign(c.get(), issuer_key, EVP_sha256()) <= 0) Fail("cannot sign the certificate of CN=" + cn);
  return c;
}

Store StoreWith(X509* ca) {
  Store s(X509_STORE_new());
  if (!s || X509_STORE_add_cert(s.get(), ca) != 1) Fail("cannot set up a certificate store");
  return s;
}

}  // namespace

KeyAndCertificate CreateCa(const std::string& common_name, int days) {
  Key key = NewKey();
  Cert cert = MakeCertificate(common_name, key.get(), nullptr, key.get(), true, days);
  return {KeyPem(key.get()), CertPem(cert.get())};
}

KeyAndCertificate CreateIdentity(const std::string& common_name, const KeyAndCertificate& ca, int days) {
  Key ca_key = ReadKey(ca.key_pem);
  Cert ca_cert = ReadCert(ca.cert_pem);
  if (!ca_key || !ca_cert) Fail("cannot read the CA's key or certificate");
  Key key = NewKey();
  Cert cert = MakeCertificate(common_name, key.get(), ca_cert.get(), ca_key.get(), false, days);
  return {KeyPem(key.get()), CertPem(cert.get())};
}

std::string SignSmime(const std::string& document, const KeyAndCertificate& signer) {
  Key key = ReadKey(signer.key_pem);
  Cert cert = ReadCert(signer.cert_pem);
  if (!key || !cert) Fail("cannot read the signer's key or certificate");
  Bio in = ReadBio(document);
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  P7 p7(PKCS7_sign(cert.get(), key.get(), nullptr, in.get(), flags));
  if (!p7) Fail("cannot sign");
  Bio out = WriteBio();
  if (SMIME_write_PKCS7(out.get(), p7.get(), in.get(), flags) != 1) Fail("cannot write the S/MIME document");
  return Text(out.get());
}

std::string VerifySmime(const std::string& smime, const std::string& ca_pem, std::string* content) {
  Cert ca = ReadCert(ca_pem);
  if (!ca) return Reason("the CA file holds no PEM certificate");
  Bio in = ReadBio(smime);
  BIO* raw_content = nullptr;
  P7 p7(SMIME_read_PKCS7(in.get(), &raw_content));
  Bio detached(raw_content);
  if (!p7) return Reason("not an S/MIME signed document");
  Store store = StoreWith(ca.get());
  Bio out = WriteBio();
  if (PKCS7_verify(p7.get(), nullptr, store.get(), detached.get(), out.get(), PKCS7_TEXT) != 1) {
    return Reason("the signature does not verify against the permissions CA");
  }
  if (content) *content = Text(out.get());
  return "";
}

std::string VerifyIdentity(const std::string& cert_pem, const std::string& key_pem, const std::string& ca_pem) {
  Cert ca = ReadCert(ca_pem);
  if (!ca) return Reason("the identity CA file holds no PEM certificate");
  Cert cert = ReadCert(cert_pem);
  if (!cert) return Reason("the identity certificate file holds no PEM certificate");
  Key key = ReadKey(key_pem);
  if (!key) return Reason("the private key file holds no PEM private key");
  if (X509_check_private_key(cert.get(), key.get()) != 1) {
    return Reason("the private key does not belong to the identity certificate");
  }
  Store store = StoreWith(ca.get());
  StoreCtx ctx(X509_STORE_CTX_new());
  if (!ctx || X509_STORE_CTX_init(ctx.get(), store.get(), cert.get(), nullptr) != 1) Fail("cannot verify");
  if (X509_verify_cert(ctx.get()) != 1) {
    const int err = X509_STORE_CTX_get_error(ctx.get());
    ERR_clear_error();
    return std::string("the identity certificate does not verify against the identity CA: ") +
           X509_verify_cert_error_string(err);
  }
  return "";
}

std::string SubjectOf(const std::string& cert_pem) {
  Cert cert = ReadCert(cert_pem);
  if (!cert) Fail("not a PEM certificate");
  Bio b = WriteBio();
  X509_NAME_print_ex(b.get(), X509_get_subject_name(cert.get()), 0, XN_FLAG_RFC2253);
  return Text(b.get());
}

}  // namespace iplan::dds::pki
