// The four writer -> reader pairings of the two DDS vendors, for the tests
// that run every combination (value-parameterised).
#pragma once

#include <ostream>
#include <string>

#include <gtest/gtest.h>

namespace iplan::testing {

struct Pairing {
  std::string writer;  // "fastdds" or "cyclonedds"
  std::string reader;
};
inline void PrintTo(const Pairing& p, std::ostream* os) { *os << p.writer << " -> " << p.reader; }

inline auto AllVendorPairings() {
  return ::testing::Values(Pairing{"fastdds", "fastdds"}, Pairing{"fastdds", "cyclonedds"},
                           Pairing{"cyclonedds", "fastdds"}, Pairing{"cyclonedds", "cyclonedds"});
}

// The test name's suffix: fastdds_to_cyclonedds.
inline std::string PairingName(const ::testing::TestParamInfo<Pairing>& info) {
  return info.param.writer + "_to_" + info.param.reader;
}

}  // namespace iplan::testing
