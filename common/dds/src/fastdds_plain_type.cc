// Rejection logging and look-up for the plain Fast DDS type support.
#include "fastdds_plain_type.h"

#include <spdlog/spdlog.h>

namespace iplan::dds::fastdds_plain {
namespace {
thread_local bool t_deserialize_failed = false;
}  // namespace

void ClearDeserializeFailure() { t_deserialize_failed = false; }
bool DeserializeFailed() { return t_deserialize_failed; }
void MarkDeserializeFailure() { t_deserialize_failed = true; }

void LogRejected(const char* dds_type, uint64_t count, const char* what) {
  spdlog::warn("Fast DDS: dropped a sample of {} that does not deserialise ({}); {} dropped so far",
               dds_type, what, count);
}

const PlainTypeEntry* FindPlainType(const std::string& dds_name) {
  for (const auto& e : AllPlainTypes()) {
    if (dds_name == e.dds_name) return &e;
  }
  return nullptr;
}

}  // namespace iplan::dds::fastdds_plain
