// FNV-1a 64-bit hashing and checksummed files, written once for the project.
//
// Two offset bases are in use, and both must stay exactly as they are:
// - kIplanFnvSeed (1469598103934665603) is the basis every iplan file format
//   and the DDS participant hash have used since the first version. It is one
//   digit short of the published FNV-1a basis, so it is NOT standard FNV-1a;
//   changing it would make every saved Q-table and intent model unreadable.
// - kStandardFnvSeed (14695981039346656037) is the published basis, used by
//   the planning benchmark's output fingerprint.
// Both use the standard 64-bit FNV prime. Hashes are of raw bytes (the
// host's, i.e. little-endian, representation of numbers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace iplan::core {

inline constexpr std::uint64_t kIplanFnvSeed = 1469598103934665603ULL;
inline constexpr std::uint64_t kStandardFnvSeed = 14695981039346656037ULL;
inline constexpr std::uint64_t kFnvPrime = 1099511628211ULL;

/// FNV-1a over `n` bytes starting from `seed` (one of the bases above, or a
/// previous result to hash a sequence of pieces). Pure, thread-safe.
std::uint64_t Fnv1a64(const void* data, std::size_t n, std::uint64_t seed);
inline std::uint64_t Fnv1a64(std::string_view bytes, std::uint64_t seed) {
  return Fnv1a64(bytes.data(), bytes.size(), seed);
}

/// Where a checksummed file keeps its 8-byte checksum (Fnv1a64 of the
/// payload with kIplanFnvSeed, host byte order):
///   kBeforePayload: header | checksum | payload   (the Q-table)
///   kAfterPayload:  header | payload | checksum   (the intent model)
/// The header (magic, version, sizes: the format's own) is not covered.
enum class ChecksumAt { kBeforePayload, kAfterPayload };

/// The complete file bytes for `header` and `payload`. Allocates.
std::string SealChecksummed(std::string_view header, std::string_view payload, ChecksumAt at);

/// The payload of `bytes` (a file sealed with the same `header_size` and
/// `at`) when its checksum matches; nullopt when the file is shorter than
/// header and checksum or the checksum does not match. The view points into
/// `bytes`. Does not look at the header: the format checks its magic.
std::optional<std::string_view> OpenChecksummed(std::string_view bytes, std::size_t header_size, ChecksumAt at);

/// WriteFileAtomically(path, SealChecksummed(header, payload, at)): a reader
/// sees the old file or the new one, and a damaged one fails its checksum.
/// Throws std::runtime_error with the path and errno text.
void WriteChecksummedFileAtomically(const std::string& path, std::string_view header, std::string_view payload,
                                    ChecksumAt at);

}  // namespace iplan::core
