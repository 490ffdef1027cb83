// The interface each DDS vendor backend implements. Internal to common/dds.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "iplan/dds/participant.h"
#include "iplan/dds/security.h"

namespace iplan::dds::internal {

class BackendWriter {
 public:
  virtual ~BackendWriter() = default;
  virtual bool Write(const void* plain, std::string* error) = 0;
  virtual int MatchedReaders() const = 0;
  virtual bool WaitForAcknowledgments(std::chrono::nanoseconds timeout) = 0;
};

class BackendReader {
 public:
  virtual ~BackendReader() = default;
  virtual bool Take(void* plain, SampleInfo* info) = 0;
  virtual void TakeEvents(std::vector<ReaderEvent>* events) = 0;
  virtual int MatchedWriters() const = 0;
};

class BackendParticipant {
 public:
  virtual ~BackendParticipant() = default;
  virtual std::unique_ptr<BackendWriter> CreateWriter(const std::string& topic,
                                                      const std::string& dds_type,
                                                      const QosProfile& qos) = 0;
  /// `owner` is what Wait() reports when this reader is ready.
  virtual std::unique_ptr<BackendReader> CreateReader(const std::string& topic,
                                                      const std::string& dds_type,
                                                      const QosProfile& qos,
                                                      AnyReader* owner) = 0;
  virtual void Wait(std::chrono::nanoseconds timeout, std::vector<AnyReader*>* ready) = 0;
  virtual void Wake() = 0;
  virtual std::vector<EndpointInfo> Endpoints() const = 0;
};

/// `config_file` may be empty (vendor default / environment);
/// `security` the participant properties that enable DDS Security (empty:
/// none; security.h).
std::unique_ptr<BackendParticipant> CreateFastDdsParticipant(const ParticipantOptions& options,
                                                             const std::string& config_file,
                                                             const Properties& security);
std::unique_ptr<BackendParticipant> CreateCycloneParticipant(const ParticipantOptions& options,
                                                             const std::string& config_file,
                                                             const Properties& security);

int64_t NowNs();
std::string HexGuid(const unsigned char* bytes, int n);
uint64_t HashBytes(const unsigned char* bytes, int n);

}  // namespace iplan::dds::internal
