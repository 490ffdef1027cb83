// Strict configuration: unknown and mistyped keys are errors naming the key
// and the file; values are validated; defaults stay when keys are absent.
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

#include "iplan/framework/config.h"

namespace iplan::framework {
namespace {

std::string FinishError(ConfigSection& c) {
  try {
    c.Finish();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, ReadsValuesAndKeepsDefaults) {
  auto c = ConfigSection::FromString("svc:\n  rate_hz: 30\n  name: cam\n  flags: [1.5, 2]\n", "svc.yaml");
  auto s = c.Section("svc");
  double rate = 1;
  std::string name;
  std::vector<double> flags;
  bool enabled = true;
  EXPECT_TRUE(s.Read("rate_hz", &rate, Positive<double>()));
  EXPECT_TRUE(s.Read("name", &name));
  EXPECT_TRUE(s.Read("flags", &flags));
  EXPECT_FALSE(s.Read("enabled", &enabled));
  EXPECT_EQ(rate, 30);
  EXPECT_EQ(name, "cam");
  EXPECT_EQ(flags, (std::vector<double>{1.5, 2}));
  EXPECT_TRUE(enabled);
  EXPECT_EQ(FinishError(c), "");
}

TEST(Config, UnknownKeyIsNamedWithFile) {
  auto c = ConfigSection::FromString("svc:\n  rate_hz: 30\n  rat_hz: 31\nother: 1\n", "cfg/svc.yaml");
  auto s = c.Section("svc");
  double rate = 1;
  s.Read("rate_hz", &rate);
  const std::string err = FinishError(c);
  EXPECT_NE(err.find("cfg/svc.yaml: unknown key 'svc.rat_hz'"), std::string::npos) << err;
  EXPECT_NE(err.find("cfg/svc.yaml: unknown key 'other'"), std::string::npos) << err;
}

TEST(Config, MistypedValueIsNamed) {
  auto c = ConfigSection::FromString("svc:\n  rate_hz: fast\n  count: 1.5\n  on: maybe\n", "svc.yaml");
  auto s = c.Section("svc");
  double rate = 1;
  int count = 0;
  bool on = false;
  EXPECT_FALSE(s.Read("rate_hz", &rate));
  EXPECT_FALSE(s.Read("count", &count));
  EXPECT_FALSE(s.Read("on", &on));
  EXPECT_EQ(rate, 1);  // unchanged on error
  ASSERT_EQ(c.Problems().size(), 3u);  // recorded at once, for tools that never call Finish
  EXPECT_NE(c.Problems()[0].find("svc.rate_hz"), std::string::npos);
  const std::string err = FinishError(c);
  EXPECT_NE(err.find("svc.yaml: key 'svc.rate_hz': expected a finite number, got 'fast'"), std::string::npos) << err;
  EXPECT_NE(err.find("key 'svc.count': expected an integer, got '1.5'"), std::string::npos) << err;
  EXPECT_NE(err.find("key 'svc.on': expected true or false, got 'maybe'"), std::string::npos) << err;
}

TEST(Config, CheckFailureAndMissingRequired) {
  auto c = ConfigSection::FromString("svc:\n  rate_hz: -3\n  mode: warp\n", "svc.yaml");
  auto s = c.Section("svc");
  double rate = 1;
  std::string mode, path;
  s.Read("rate_hz", &rate, Positive<double>());
  s.Read("mode", &mode, OneOf({"replay", "synthetic"}));
  s.Require("path", &path);
  const std::string err = FinishError(c);
  EXPECT_NE(err.find("key 'svc.rate_hz': must be > 0 (got '-3')"), std::string::npos) << err;
  EXPECT_NE(err.find("key 'svc.mode': must be one of: replay synthetic"), std::string::npos) << err;
  EXPECT_NE(err.find("key 'svc.path': is required but missing"), std::string::npos) << err;
}

TEST(Config, SectionThatIsNotAMapping) {
  auto c = ConfigSection::FromString("svc: 3\n", "svc.yaml");
  c.Section("svc");
  EXPECT_NE(FinishError(c).find("key 'svc': expected a mapping, got '3'"), std::string::npos);
}

TEST(Config, SyntaxErrorNamesLine) {
  try {
    ConfigSection::FromString("svc:\n  a: [1, 2\n", "bad.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml: line"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ConfigSection::Load("/nonexistent/x.yaml"), ConfigError);
}

TEST(Config, AKeyWrittenTwiceIsAnErrorAtAnyDepth) {
  // yaml-cpp would keep the first value and ignore the edit further down.
  auto error = [](const std::string& yaml) {
    try {
      ConfigSection::FromString(yaml, "cfg/svc.yaml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("svc:\n  rate_hz: 30\nsvc:\n  rate_hz: 15\n"), "cfg/svc.yaml: key 'svc': appears twice (lines 1 and 3)");
  EXPECT_EQ(error("svc:\n  rate_hz: 30\n  name: cam\n  rate_hz: 15\n"),
            "cfg/svc.yaml: key 'svc.rate_hz': appears twice (lines 2 and 4)");
  EXPECT_EQ(error("svc:\n  cams:\n    - {id: 1, id: 2}\n"), "cfg/svc.yaml: key 'svc.cams[0].id': appears twice (lines 3 and 3)");
  EXPECT_EQ(error("svc:\n  rate_hz: 30\nother:\n  rate_hz: 30\n"), "");  // the same name in two mappings is fine
  auto c = ConfigSection::FromString("svc:\n  a: 1\n", "svc.yaml");
  EXPECT_THROW(c.Override("svc.b", "{x: 1, x: 2}"), ConfigError);
}

TEST(Config, AnEmptyFileIsAnErrorButAnEmptyMappingIsNot) {
  for (const std::string yaml : {"", "\n\n", "# svc:\n#   rate_hz: 30\n", "~\n", "null\n", "---\n"}) {
    try {
      ConfigSection::FromString(yaml, "cfg/svc.yaml");
      ADD_FAILURE() << "accepted '" << yaml << "'";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), "cfg/svc.yaml: the file is empty") << yaml;
    }
  }
  auto c = ConfigSection::FromString("{}", "(no configuration file)");
  EXPECT_TRUE(c.Keys().empty());
  EXPECT_EQ(FinishError(c), "");
  const std::string path = testing::TempDir() + "iplan-empty-config.yaml";
  std::ofstream(path) << "# nothing yet\n";
  try {
    ConfigSection::Load(path);
    ADD_FAILURE() << "an empty file was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": the file is empty");
  }
  std::remove(path.c_str());
}

TEST(Config, OverridesReplaceAndCreateValuesAndAreCheckedLikeTheFile) {
  auto c = ConfigSection::FromString("svc:\n  rate_hz: 30\n  sub:\n    a: 1\n", "svc.yaml");
  c.Override("svc.rate_hz", "15");
  c.Override("svc.sub.b", "[1, 2]");
  c.Override("svc.new.deep", "x");
  c.Override("svc.rate_hz.x", "1");  // kept for a parameter file named rate_hz: there is none
  EXPECT_THROW(c.Override("svc.sub.a", "[1,"), ConfigError);      // not YAML
  EXPECT_THROW(c.Override("svc..a", "1"), ConfigError);
  auto s = c.Section("svc");
  EXPECT_EQ(s.Keys(), (std::vector<std::string>{"rate_hz", "sub", "new"}));
  double rate = 0;
  std::vector<double> b;
  int a = 0;
  std::string deep;
  s.Read("rate_hz", &rate);
  auto sub = s.Section("sub");
  sub.Read("a", &a);
  sub.Read("b", &b);
  EXPECT_EQ(rate, 15);
  EXPECT_EQ(a, 1);
  EXPECT_EQ(b, (std::vector<double>{1, 2}));
  // An overridden key nobody reads is reported like a typo in the file, and
  // one into a value that names no parameter file likewise.
  EXPECT_NE(FinishError(c).find("svc.new"), std::string::npos);
  EXPECT_NE(FinishError(c).find("--set svc.rate_hz.x=1: 'svc.rate_hz' is a value, not a mapping or a parameter file"),
            std::string::npos)
      << FinishError(c);
}

TEST(Config, PathsResolveAgainstTheFilesFolder) {
  const auto c = ConfigSection::FromString("a: 1", "/etc/iplan/supervisor.yaml");
  EXPECT_EQ(c.ResolvePath("tasks/table_top.yaml"), "/etc/iplan/tasks/table_top.yaml");
  EXPECT_EQ(c.ResolvePath("../shared/x.csv"), "/etc/shared/x.csv");
  EXPECT_EQ(c.ResolvePath("/var/lib/iplan/q_table.bin"), "/var/lib/iplan/q_table.bin");
  EXPECT_EQ(c.ResolvePath(""), "");
  EXPECT_TRUE(c.Problems().empty());
  const auto rel = ConfigSection::FromString("a: 1", "config/intent.yaml");
  EXPECT_EQ(rel.ResolvePath("models/m.model"), "config/models/m.model");
}

}  // namespace
}  // namespace iplan::framework
