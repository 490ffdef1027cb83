// Every IDL type crosses process boundaries field by field equal, in all
// four vendor pairings (Fast DDS and Cyclone DDS, writer and reader).
#include <gtest/gtest.h>

#include "test_paths.h"
#include "vendor_pairings.h"

namespace iplan::testing {
namespace {


class DdsInterop : public ::testing::TestWithParam<Pairing> {};

TEST_P(DdsInterop, EveryTypeRoundTripsFieldByField) {
  const Pairing p = GetParam();
  const std::string domain = std::to_string(UniqueDomain(static_cast<int>(p.writer.size() * 3 + p.reader.size())));
  Process sub({TestBinPath("dds_probe"), "roundtrip-sub", "--dds", p.reader, "--domain", domain,
               "--seed", "17", "--samples", "3", "--timeout", "60"});
  ASSERT_TRUE(sub.WaitForOutput("ready", std::chrono::seconds(20))) << sub.Stderr();
  Process pub({TestBinPath("dds_probe"), "roundtrip-pub", "--dds", p.writer, "--domain", domain,
               "--seed", "17", "--samples", "3", "--timeout", "60"});
  const auto sub_rc = sub.Wait(std::chrono::seconds(90));
  ASSERT_TRUE(sub_rc.has_value()) << "reader did not finish\n" << sub.Stdout();
  EXPECT_EQ(*sub_rc, 0) << sub.Stdout() << sub.Stderr();
  EXPECT_NE(sub.Stdout().find("ALL OK"), std::string::npos) << sub.Stdout();
  EXPECT_NE(sub.Stdout().find("OK HumanPrediction 3"), std::string::npos) << sub.Stdout();
  const auto pub_rc = pub.Wait(std::chrono::seconds(30));
  ASSERT_TRUE(pub_rc.has_value());
  EXPECT_EQ(*pub_rc, 0) << pub.Stdout() << pub.Stderr();
}

INSTANTIATE_TEST_SUITE_P(AllPairings, DdsInterop, AllVendorPairings(), PairingName);

}  // namespace
}  // namespace iplan::testing
