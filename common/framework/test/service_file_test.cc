// framework::ServiceFile: a service's file read as the service reads it, by
// the services and by every tool (one loader).
#include "iplan/framework/service_file.h"

#include <fstream>

#include <gtest/gtest.h>

namespace iplan::framework {
namespace {

struct Section {
  double rate_hz = 10;
  std::string name = "a";
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(rate_hz, "Hz, > 0"));
    a->Visit(IPLAN_NVP(name, "a name"));
  }
  std::string Validate() const { return rate_hz > 0 ? "" : "rate_hz must be > 0, got " + core::ParamText(rate_hz); }
};

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

std::string Error(const std::string& path, const core::Overrides& overrides = {}) {
  try {
    Section s;
    ServiceFile(path, overrides).ReadSection("svc", &s).Finish();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ServiceFile, ReadsTheNodeSectionAndDeclaredSectionsWithOverrides) {
  const std::string path = Write("svc.yaml",
                                 "node:\n  diagnostics_period: 2.5\n  remap: {/iplan/a: /iplan/b}\n"
                                 "  entitled_writers: {/iplan/robot/trajectory: [iplan-trajopt]}\nsvc:\n  rate_hz: 30\n");
  ServiceFile f(path, {{"svc.name", "b"}});
  Section s;
  f.ReadSection("svc", &s).Finish();
  EXPECT_EQ(s.rate_hz, 30);
  EXPECT_EQ(s.name, "b");
  EXPECT_EQ(f.node().options.diagnostics_period, 2.5);
  EXPECT_EQ(f.node().options.frame_id, "world");  // the default
  EXPECT_EQ(f.node().remap.at("/iplan/a"), "/iplan/b");
  EXPECT_EQ(f.node().options.entitled_writers.at("/iplan/robot/trajectory"), std::vector<std::string>{"iplan-trajopt"});
  EXPECT_EQ(CellFile("/etc/iplan", "perception"), "/etc/iplan/perception.yaml");
}

TEST(ServiceFile, UnknownKeysWrongTypesAndRangesAreRefusedNamingFileAndKey) {
  const std::string unknown = Write("svc_unknown.yaml", "svc:\n  rat_hz: 3\n");
  EXPECT_EQ(Error(unknown), unknown + ": unknown key 'svc.rat_hz'");
  const std::string node = Write("svc_node.yaml", "node:\n  realtime_priority: 120\n");
  EXPECT_EQ(Error(node), node + ": section 'node': realtime_priority must be in 0..99, got 120");
  const std::string range = Write("svc_range.yaml", "svc:\n  rate_hz: 0\n");
  EXPECT_EQ(Error(range), range + ": section 'svc': rate_hz must be > 0, got 0.0");
  const std::string ok = Write("svc_ok.yaml", "svc:\n  rate_hz: 5\n");
  EXPECT_EQ(Error(ok, {{"svc.rate_hz", "fast"}}), ok + ": key 'svc.rate_hz': expected a finite number, got 'fast'");
  EXPECT_EQ(Error(ok), "");
  // A section nobody declared is an unknown key too.
  const std::string other = Write("svc_other.yaml", "svc:\n  rate_hz: 5\nother:\n  x: 1\n");
  EXPECT_EQ(Error(other), other + ": unknown key 'other'");
}

TEST(NodeSettings, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(NodeSettings{})),
            "");
}

}  // namespace
}  // namespace iplan::framework
