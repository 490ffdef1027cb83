#include "iplan/dds/participant.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "backend.h"
#include "iplan/core/checksum.h"

namespace iplan::dds {
namespace internal {

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string HexGuid(const unsigned char* bytes, int n) {
  static const char* kHex = "0123456789abcdef";
  std::string s;
  for (int i = 0; i < n; ++i) {
    if (i == 4 || i == 8 || i == 12) s += '.';
    s += kHex[bytes[i] >> 4];
    s += kHex[bytes[i] & 15];
  }
  return s;
}

uint64_t HashBytes(const unsigned char* bytes, int n) {
  return core::Fnv1a64(bytes, static_cast<std::size_t>(n), core::kIplanFnvSeed);
}

}  // namespace internal

namespace {
constexpr char kUserDataPrefix[] = "iplan.name=";
}  // namespace

std::string WriterUserData(const std::string& participant_name) { return kUserDataPrefix + participant_name; }

std::string NameFromUserData(const unsigned char* bytes, std::size_t size) {
  const std::size_t n = sizeof(kUserDataPrefix) - 1;
  if (bytes == nullptr || size <= n || std::char_traits<char>::compare(reinterpret_cast<const char*>(bytes), kUserDataPrefix, n) != 0) {
    return "";
  }
  // Names are short; a longer claim is not one of ours.
  if (size - n > 128) return "";
  return std::string(reinterpret_cast<const char*>(bytes) + n, size - n);
}

namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool FileExists(const std::string& path) { return std::ifstream(path).good(); }

// The vendor configuration a participant uses; see ParticipantOptions.
std::string ResolveConfig(const ParticipantOptions& o) {
  if (!o.config_file.empty()) {
    if (!FileExists(o.config_file)) throw std::runtime_error("DDS config file not found: " + o.config_file);
    return o.config_file;
  }
  const char* vendor_env = o.vendor == Vendor::kCyclone ? "CYCLONEDDS_URI" : "FASTRTPS_DEFAULT_PROFILES_FILE";
  if (const char* v = std::getenv(vendor_env); v && *v) return "";  // the vendor reads it itself
  const char* profile_env = std::getenv("IPLAN_DDS_PROFILE");
  const std::string profile = profile_env && *profile_env ? profile_env : "loopback";
  const std::string file = (o.vendor == Vendor::kCyclone ? "cyclonedds-" : "fastdds-") + profile + ".xml";
  std::vector<std::string> dirs;
  if (const char* d = std::getenv("IPLAN_CONFIG_DIR"); d && *d) dirs.push_back(std::string(d) + "/dds");
  dirs.push_back(IPLAN_INSTALL_CONFIG_DIR "/dds");
  dirs.push_back(IPLAN_SOURCE_CONFIG_DIR "/dds");
  for (const auto& d : dirs) {
    if (FileExists(d + "/" + file)) return d + "/" + file;
  }
  throw std::runtime_error("DDS profile '" + profile + "': " + file + " not found in $IPLAN_CONFIG_DIR/dds, " +
                           IPLAN_INSTALL_CONFIG_DIR "/dds or " IPLAN_SOURCE_CONFIG_DIR "/dds");
}

}  // namespace

std::string ToString(Vendor vendor) { return vendor == Vendor::kCyclone ? "cyclonedds" : "fastdds"; }

Vendor ParseVendor(const std::string& text) {
  const std::string t = Lower(text);
  if (t == "cyclonedds" || t == "cyclone" || t == "rmw_cyclonedds_cpp") return Vendor::kCyclone;
  if (t == "fastdds" || t == "fastrtps" || t == "rmw_fastrtps_cpp") return Vendor::kFastDds;
  throw std::invalid_argument("unknown DDS vendor '" + text + "' (use cyclonedds or fastdds)");
}

Vendor DefaultVendor() {
  const char* v = std::getenv("IPLAN_DDS");
  if (!v || !*v) return Vendor::kCyclone;
  try {
    return ParseVendor(v);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("IPLAN_DDS: ") + e.what());
  }
}

int DefaultDomain() {
  const char* v = std::getenv("IPLAN_DOMAIN");
  if (!v || !*v) return 0;
  char* end = nullptr;
  const long d = std::strtol(v, &end, 10);
  if (*end != '\0' || d < 0 || d > 232) {
    throw std::invalid_argument(std::string("IPLAN_DOMAIN '") + v + "' is not a domain id in [0, 232]");
  }
  return static_cast<int>(d);
}

std::string ToString(EventKind kind) {
  switch (kind) {
    case EventKind::kDeadlineMissed: return "deadline missed";
    case EventKind::kLivelinessLost: return "liveliness lost";
    case EventKind::kLivelinessRegained: return "liveliness regained";
    case EventKind::kMatched: return "writer matched";
    case EventKind::kUnmatched: return "writer unmatched";
    case EventKind::kIncompatibleQos: return "incompatible QoS";
  }
  return "unknown";
}

std::unique_ptr<Participant> Participant::Create(const ParticipantOptions& options) {
  if (options.domain_id < 0 || options.domain_id > 232) {
    throw std::invalid_argument("domain id " + std::to_string(options.domain_id) + " not in [0, 232]");
  }
  std::unique_ptr<Participant> p(new Participant());
  p->options_ = options;
  p->config_used_ = ResolveConfig(options);
  Properties security;
  if (!options.security_dir.empty()) {
    const EnclaveFiles files = LoadEnclave(options.security_dir, options.enclave.empty() ? options.name : options.enclave);
    security = options.vendor == Vendor::kCyclone ? CycloneSecurityProperties(files) : FastDdsSecurityProperties(files);
  }
  p->backend_ = options.vendor == Vendor::kCyclone
                    ? internal::CreateCycloneParticipant(options, p->config_used_, security)
                    : internal::CreateFastDdsParticipant(options, p->config_used_, security);
  return p;
}

Participant::~Participant() = default;

void Participant::Wait(std::chrono::nanoseconds timeout, std::vector<AnyReader*>* ready) {
  backend_->Wait(timeout, ready);
}

void Participant::Wake() { backend_->Wake(); }

std::vector<EndpointInfo> Participant::Endpoints() const { return backend_->Endpoints(); }

AnyWriter::AnyWriter(Participant& participant, const std::string& topic, const std::string& dds_type,
                     const QosProfile& qos)
    : topic_(topic) {
  if (const std::string why = qos.Validate(); !why.empty()) {
    throw std::invalid_argument("QoS for " + topic + ": " + why);
  }
  impl_ = participant.backend().CreateWriter(topic, dds_type, qos);
}

AnyWriter::~AnyWriter() = default;

bool AnyWriter::WriteAny(const void* plain, std::string* error) { return impl_->Write(plain, error); }

int AnyWriter::MatchedReaders() const { return impl_->MatchedReaders(); }

bool AnyWriter::WaitForReaders(int count, std::chrono::nanoseconds timeout) const {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (impl_->MatchedReaders() < count) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

bool AnyWriter::WaitForAcknowledgments(std::chrono::nanoseconds timeout) {
  return impl_->WaitForAcknowledgments(timeout);
}

AnyReader::AnyReader(Participant& participant, const std::string& topic, const std::string& dds_type,
                     const QosProfile& qos)
    : topic_(topic), type_(dds_type) {
  if (const std::string why = qos.Validate(); !why.empty()) {
    throw std::invalid_argument("QoS for " + topic + ": " + why);
  }
  impl_ = participant.backend().CreateReader(topic, dds_type, qos, this);
}

AnyReader::~AnyReader() = default;

bool AnyReader::TakeAny(void* plain, SampleInfo* info) { return impl_->Take(plain, info); }

std::vector<ReaderEvent> AnyReader::TakeEvents() {
  std::vector<ReaderEvent> events;
  impl_->TakeEvents(&events);
  return events;
}

int AnyReader::MatchedWriters() const { return impl_->MatchedWriters(); }

}  // namespace iplan::dds
