#include "iplan/core/checksum.h"

#include <cstring>

#include "iplan/core/atomic_file.h"

namespace iplan::core {

std::uint64_t Fnv1a64(const void* data, std::size_t n, std::uint64_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = seed;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= kFnvPrime;
  }
  return h;
}

std::string SealChecksummed(std::string_view header, std::string_view payload, ChecksumAt at) {
  const std::uint64_t sum = Fnv1a64(payload, kIplanFnvSeed);
  char sum_bytes[sizeof sum];
  std::memcpy(sum_bytes, &sum, sizeof sum);
  std::string out;
  out.reserve(header.size() + sizeof sum + payload.size());
  out.append(header);
  if (at == ChecksumAt::kBeforePayload) out.append(sum_bytes, sizeof sum);
  out.append(payload);
  if (at == ChecksumAt::kAfterPayload) out.append(sum_bytes, sizeof sum);
  return out;
}

std::optional<std::string_view> OpenChecksummed(std::string_view bytes, std::size_t header_size, ChecksumAt at) {
  constexpr std::size_t kSum = sizeof(std::uint64_t);
  if (bytes.size() < header_size + kSum) return std::nullopt;
  const std::size_t payload_size = bytes.size() - header_size - kSum;
  const std::size_t sum_at = at == ChecksumAt::kBeforePayload ? header_size : header_size + payload_size;
  const std::size_t payload_at = at == ChecksumAt::kBeforePayload ? header_size + kSum : header_size;
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + sum_at, kSum);
  const std::string_view payload = bytes.substr(payload_at, payload_size);
  if (Fnv1a64(payload, kIplanFnvSeed) != stored) return std::nullopt;
  return payload;
}

void WriteChecksummedFileAtomically(const std::string& path, std::string_view header, std::string_view payload,
                                    ChecksumAt at) {
  WriteFileAtomically(path, SealChecksummed(header, payload, at));
}

}  // namespace iplan::core
