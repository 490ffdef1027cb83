// One C++ interface to DDS with two run-time selectable backends: Fast DDS
// (the plain types serialised directly with Fast CDR) and Cyclone DDS (idlc C
// structs, converted to and from). Callers only see iplan::msg types.
//
// Threading model: a Participant owns one wait set. Readers never call back
// on vendor threads; the owner of the participant (usually the service
// framework's executor, one thread) calls Wait() and then Take()/TakeEvents()
// on the readers it reports ready. Writers may be used from any thread.
//
//   auto p = Participant::Create({.vendor = Vendor::kCyclone});
//   auto w = CreateWriter<msg::HumanSkeleton>(*p, "rt/iplan/human/skeleton", qos);
//   auto r = CreateReader<msg::HumanSkeleton>(*p, "rt/iplan/human/skeleton", qos);
//   std::vector<AnyReader*> ready;
//   p->Wait(100ms, &ready);
//   msg::HumanSkeleton s; SampleInfo info;
//   while (r->Take(&s, &info)) { ... }
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "iplan/dds/qos.h"
#include "iplan/msg/types.h"

namespace iplan::dds {

enum class Vendor { kCyclone, kFastDds };

/// "cyclonedds" or "fastdds".
std::string ToString(Vendor vendor);
/// Accepts "cyclonedds", "cyclone", "fastdds", "fastrtps" (case-insensitive).
/// Throws std::invalid_argument naming the accepted values otherwise.
Vendor ParseVendor(const std::string& text);
/// IPLAN_DDS from the environment (like ROS 2's RMW_IMPLEMENTATION), else
/// Cyclone DDS. Throws std::invalid_argument when IPLAN_DDS is not a vendor.
Vendor DefaultVendor();
/// IPLAN_DOMAIN from the environment, else 0. Throws when not in [0, 232].
int DefaultDomain();

struct ParticipantOptions {
  Vendor vendor = Vendor::kCyclone;
  int domain_id = 0;  ///< [0, 232]
  std::string name = "iplan";
  /// Vendor configuration file (Cyclone XML or Fast DDS XML profiles). Empty:
  /// the vendor's own environment variable (CYCLONEDDS_URI,
  /// FASTRTPS_DEFAULT_PROFILES_FILE) when set, else the shipped
  /// config/dds/<vendor>-<IPLAN_DDS_PROFILE>.xml, IPLAN_DDS_PROFILE defaulting
  /// to "loopback" (discovery and data on 127.0.0.1 only).
  std::string config_file;
  /// Keep track of every endpoint on the domain (for `iplan topic list`).
  bool track_endpoints = false;
  /// DDS Security keystore folder (iplan/dds/security.h); empty: no
  /// security. The participant authenticates as enclave `enclave` (empty:
  /// `name`), and Create throws when that enclave is missing or invalid.
  std::string security_dir;
  std::string enclave;
  // `name` is also announced in every writer's USER_DATA (WriterUserData), so
  // readers can tell which participant wrote a sample (SampleInfo::writer_name).
};

/// Metadata of a received sample.
struct SampleInfo {
  int64_t source_timestamp_ns = 0;  ///< writer's clock, ns since the epoch
  int64_t reception_ns = 0;         ///< our system clock at Take(), ns since the epoch
  uint64_t writer_id = 0;           ///< stable per remote writer (hash of its GUID)
  /// Name of the participant that owns the writer, as the writer announced it
  /// at discovery (USER_DATA "iplan.name=<ParticipantOptions::name>"); empty
  /// when it announced none (e.g. a ROS 2 node). Without DDS Security anyone
  /// can claim any name: it tells iplan's own services apart and keeps
  /// strangers that do not pretend out; it is no authentication.
  std::string writer_name;
};

/// The USER_DATA every iplan writer announces: "iplan.name=" + participant name.
std::string WriterUserData(const std::string& participant_name);
/// The participant name in a writer's USER_DATA, or "" when it is not ours.
std::string NameFromUserData(const unsigned char* bytes, std::size_t size);

/// Status changes a reader reports (counts are cumulative per reader).
enum class EventKind {
  kDeadlineMissed,     ///< a writer missed the DEADLINE period
  kLivelinessLost,     ///< a writer stopped asserting liveliness (crashed or hung)
  kLivelinessRegained, ///< a writer is alive again / a new writer became alive
  kMatched,            ///< a writer matched this reader
  kUnmatched,          ///< a writer left
  kIncompatibleQos,    ///< a writer on the topic offers incompatible QoS
};
std::string ToString(EventKind kind);

struct ReaderEvent {
  EventKind kind;
  int32_t total_count = 0;   ///< cumulative count of this kind
  int32_t count_change = 0;  ///< change since the last report
  int32_t current = 0;       ///< alive writers (liveliness) / matched writers
};

/// A topic endpoint seen on the domain.
struct EndpointInfo {
  std::string topic;
  std::string type;
  bool is_writer = false;
  std::string guid;
};

namespace internal {
class BackendParticipant;
class BackendReader;
class BackendWriter;
}  // namespace internal

class AnyReader;

class Participant {
 public:
  /// Creates a participant on the chosen vendor and domain. Throws
  /// std::runtime_error with the vendor's reason (bad config file, no
  /// network interface, ...).
  static std::unique_ptr<Participant> Create(const ParticipantOptions& options);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  Vendor vendor() const { return options_.vendor; }
  int domain_id() const { return options_.domain_id; }
  /// The vendor configuration actually used ("" when the vendor default).
  const std::string& config_used() const { return config_used_; }

  /// Blocks until a reader of this participant has data or a status change,
  /// Wake() is called, or `timeout` passes. Appends the ready readers to
  /// `ready` (cleared first). One thread at a time.
  void Wait(std::chrono::nanoseconds timeout, std::vector<AnyReader*>* ready);
  /// Makes a current or the next Wait() return. Thread-safe.
  void Wake();
  /// Endpoints on the domain known so far (needs track_endpoints).
  std::vector<EndpointInfo> Endpoints() const;

  internal::BackendParticipant& backend() { return *backend_; }

 private:
  Participant() = default;
  ParticipantOptions options_;
  std::string config_used_;
  std::unique_ptr<internal::BackendParticipant> backend_;
};

/// Type-erased writer; `Writer<T>` is the typed face.
class AnyWriter {
 public:
  /// `dds_type` is the DDS type name (msg::TypeName<T>::kDds). Throws
  /// std::runtime_error when the topic or writer cannot be created (e.g. the
  /// topic exists with another type).
  AnyWriter(Participant& participant, const std::string& topic, const std::string& dds_type,
            const QosProfile& qos);
  ~AnyWriter();
  /// Serialises and sends; `plain` points to the iplan::msg type. False with
  /// a reason in `error` when the vendor refused (e.g. timeout). Thread-safe.
  bool WriteAny(const void* plain, std::string* error = nullptr);
  /// Readers currently matched.
  int MatchedReaders() const;
  /// Waits until at least `count` readers match; false on timeout.
  bool WaitForReaders(int count, std::chrono::nanoseconds timeout) const;
  /// Waits until every matched reliable reader acknowledged what was written.
  bool WaitForAcknowledgments(std::chrono::nanoseconds timeout);
  const std::string& topic() const { return topic_; }

 private:
  std::string topic_;
  std::unique_ptr<internal::BackendWriter> impl_;
};

template <class T>
class Writer : public AnyWriter {
 public:
  Writer(Participant& p, const std::string& topic, const QosProfile& qos)
      : AnyWriter(p, topic, msg::TypeName<T>::kDds, qos) {}
  bool Write(const T& m, std::string* error = nullptr) { return WriteAny(&m, error); }
};

/// Type-erased reader; `Reader<T>` is the typed face.
class AnyReader {
 public:
  AnyReader(Participant& participant, const std::string& topic, const std::string& dds_type,
            const QosProfile& qos);
  virtual ~AnyReader();
  /// Takes the oldest sample into `plain` (an iplan::msg type of this
  /// reader's type). False when there is none. Not thread-safe.
  bool TakeAny(void* plain, SampleInfo* info);
  /// Status changes since the last call (deadline, liveliness, matching).
  std::vector<ReaderEvent> TakeEvents();
  int MatchedWriters() const;
  const std::string& topic() const { return topic_; }
  const std::string& type() const { return type_; }

 private:
  std::string topic_;
  std::string type_;
  std::unique_ptr<internal::BackendReader> impl_;
};

template <class T>
class Reader : public AnyReader {
 public:
  Reader(Participant& p, const std::string& topic, const QosProfile& qos)
      : AnyReader(p, topic, msg::TypeName<T>::kDds, qos) {}
  bool Take(T* m, SampleInfo* info = nullptr) {
    SampleInfo local;
    return TakeAny(m, info ? info : &local);
  }
};

}  // namespace iplan::dds
