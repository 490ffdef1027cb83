#include "iplan/core/checksum.h"

#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

#include "iplan/core/atomic_file.h"

namespace iplan::core {
namespace {

TEST(Fnv1a64, StandardSeedGivesThePublishedTestVectors) {
  EXPECT_EQ(kStandardFnvSeed, 0xcbf29ce484222325ULL);
  EXPECT_EQ(Fnv1a64("", kStandardFnvSeed), 0xcbf29ce484222325ULL);
  EXPECT_EQ(Fnv1a64("a", kStandardFnvSeed), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(Fnv1a64("foobar", kStandardFnvSeed), 0x85944171f73967e8ULL);
}

TEST(Fnv1a64, IplanSeedKeepsTheValuesSavedFilesCarry) {
  // Values computed independently (Python) with basis 1469598103934665603:
  // the checksum of every saved Q-table and intent model depends on them.
  EXPECT_EQ(kIplanFnvSeed, 1469598103934665603ULL);
  EXPECT_EQ(Fnv1a64("graph", kIplanFnvSeed), 0x4c54015229526131ULL);
  EXPECT_EQ(Fnv1a64("IPLQTBL2", kIplanFnvSeed), 0x4e278a126efe13f1ULL);
  // Chaining through the seed hashes the concatenation.
  EXPECT_EQ(Fnv1a64("bar", Fnv1a64("foo", kStandardFnvSeed)), Fnv1a64("foobar", kStandardFnvSeed));
}

TEST(Checksummed, SealsBeforeOrAfterThePayloadAndOpensOnlyAnIntactFile) {
  const std::string header = "HDR", payload = "payload bytes";
  const std::uint64_t sum = Fnv1a64(payload, kIplanFnvSeed);
  const std::string sum_bytes(reinterpret_cast<const char*>(&sum), 8);
  const std::string before = SealChecksummed(header, payload, ChecksumAt::kBeforePayload);
  const std::string after = SealChecksummed(header, payload, ChecksumAt::kAfterPayload);
  EXPECT_EQ(before, header + sum_bytes + payload);
  EXPECT_EQ(after, header + payload + sum_bytes);
  EXPECT_EQ(OpenChecksummed(before, 3, ChecksumAt::kBeforePayload).value(), payload);
  EXPECT_EQ(OpenChecksummed(after, 3, ChecksumAt::kAfterPayload).value(), payload);
  // The wrong placement, a flipped payload byte or a truncated file fail.
  EXPECT_FALSE(OpenChecksummed(before, 3, ChecksumAt::kAfterPayload).has_value());
  std::string flipped = after;
  flipped[5] ^= 1;
  EXPECT_FALSE(OpenChecksummed(flipped, 3, ChecksumAt::kAfterPayload).has_value());
  EXPECT_FALSE(OpenChecksummed(after.substr(0, 10), 3, ChecksumAt::kAfterPayload).has_value());
  EXPECT_FALSE(OpenChecksummed("HDR1234", 3, ChecksumAt::kAfterPayload).has_value());
  // The header is the format's: not covered by the checksum.
  std::string other_header = after;
  other_header[0] = 'X';
  EXPECT_TRUE(OpenChecksummed(other_header, 3, ChecksumAt::kAfterPayload).has_value());
}

TEST(Checksummed, WritesAtomically) {
  const auto dir = std::filesystem::temp_directory_path() / ("iplan-sum-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "f.bin").string();
  WriteChecksummedFileAtomically(path, "H", "abc", ChecksumAt::kAfterPayload);
  EXPECT_EQ(ReadFile(path), SealChecksummed("H", "abc", ChecksumAt::kAfterPayload));
  EXPECT_THROW(WriteChecksummedFileAtomically((dir / "no/such/f.bin").string(), "H", "abc",
                                              ChecksumAt::kAfterPayload),
               std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace iplan::core
