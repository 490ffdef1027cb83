#include "iplan/core/params.h"

#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

namespace iplan::core {
namespace {

struct Inner {
  double gain = 2.0;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(gain, "dimensionless, >= 0"));
  }
};

struct Demo {
  double dt = 0.1;
  int count = 3;
  std::uint64_t seed = 7;
  bool on = true;
  std::string name = "panda_link8";
  std::array<double, 3> offset = {0.0, 0.0, 0.5};
  std::vector<std::pair<std::string, std::string>> pairs = {{"a", "b"}};
  Inner inner;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(dt, "s; > 0"));
    a->Visit(IPLAN_NVP(count, ">= 1"));
    a->Visit(IPLAN_NVP(seed, "generator seed"));
    a->Visit(IPLAN_NVP(on, "switch"));
    a->Visit(IPLAN_NVP(name, "a link"));
    a->Visit(IPLAN_NVP(offset, "m; [x, y, z]"));
    a->Visit(IPLAN_NVP(pairs, "[a, b] pairs"));
    a->Visit(IPLAN_NVP(inner, "nested"));
  }
  std::string Validate() const {
    if (!(dt > 0)) return "dt must be > 0";
    if (count < 1) return "count must be >= 1";
    return "";
  }
};

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

std::string LoadError(const std::string& path, const Overrides& o = {}) {
  try {
    LoadParamsFile<Demo>(path, o);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Params, LoadsEveryFieldTypeAndNestedStructs) {
  const std::string path = Write("demo.yaml",
                                 "dt: 0.05\ncount: 4\nseed: 18446744073709551615\non: false\nname: tool\n"
                                 "offset: [1, 2, 3]\npairs: [[x, y], [z, w]]\ninner: {gain: 0.5}\n");
  const Demo d = LoadParamsFile<Demo>(path);
  EXPECT_EQ(d.dt, 0.05);
  EXPECT_EQ(d.count, 4);
  EXPECT_EQ(d.seed, 18446744073709551615ULL);
  EXPECT_FALSE(d.on);
  EXPECT_EQ(d.name, "tool");
  EXPECT_EQ(d.offset, (std::array<double, 3>{1, 2, 3}));
  ASSERT_EQ(d.pairs.size(), 2u);
  EXPECT_EQ(d.pairs[1], (std::pair<std::string, std::string>{"z", "w"}));
  EXPECT_EQ(d.inner.gain, 0.5);
  // An empty parameter file is all defaults.
  EXPECT_EQ(LoadParamsFile<Demo>(Write("empty.yaml", "# nothing\n")).count, 3);
}

TEST(Params, UnknownKeysWrongTypesAndValidateAreErrorsNamingFileAndKey) {
  const std::string unknown = Write("unknown.yaml", "dt: 0.1\ninner: {gain: 1, gian: 2}\nfoo: 1\n");
  EXPECT_EQ(LoadError(unknown), unknown + ": unknown key 'inner.gian'\n" + unknown + ": unknown key 'foo'");
  const std::string type = Write("type.yaml", "count: many\n");
  EXPECT_EQ(LoadError(type), type + ": key 'count': expected an integer, got 'many'");
  const std::string size = Write("size.yaml", "offset: [1, 2]\n");
  EXPECT_EQ(LoadError(size), size + ": key 'offset': expected 3 numbers, got 2");
  const std::string neg = Write("neg.yaml", "seed: -1\n");
  EXPECT_EQ(LoadError(neg), neg + ": key 'seed': expected an integer >= 0, got '-1'");
  const std::string pair = Write("pair.yaml", "pairs: [[a, b, c]]\n");
  EXPECT_EQ(LoadError(pair), pair + ": key 'pairs[0]': expected a pair [a, b] of strings, got a list");
  const std::string invalid = Write("invalid.yaml", "dt: 0\n");
  EXPECT_EQ(LoadError(invalid), invalid + ": dt must be > 0");
  const std::string twice = Write("twice.yaml", "dt: 0.1\ndt: 0.2\n");
  EXPECT_EQ(LoadError(twice), twice + ": key 'dt': appears twice (lines 1 and 2)");
}

// A mapping of name: struct keeps the file's order (not sorted), replaces the
// default entries, and checks each entry's keys; a mapping of strings or of
// lists is read whole.
struct Catalogue {
  Named<Inner> gains = {{"default", Inner{}}};
  std::map<std::string, std::string> renames;
  std::map<std::string, std::vector<std::string>> lists;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(gains, "name: gain"));
    a->Visit(IPLAN_NVP(renames, "from: to"));
    a->Visit(IPLAN_NVP(lists, "name: [items]"));
  }
  std::string Validate() const { return ""; }
};

TEST(Params, NamedStructsKeepTheFilesOrderAndMappingsReadWhole) {
  const std::string path = Write("named.yaml",
                                 "gains: {zeta: {gain: 1}, alpha: {gain: 3}, mid: {}}\n"
                                 "renames: {wrist_r: hand_r}\nlists: {/t: [a, b]}\n");
  const Catalogue c = LoadParamsFile<Catalogue>(path);
  ASSERT_EQ(c.gains.size(), 3u);
  EXPECT_EQ(c.gains[0].first, "zeta");
  EXPECT_EQ(c.gains[1].first, "alpha");
  EXPECT_EQ(c.gains[1].second.gain, 3.0);
  EXPECT_EQ(c.gains[2].second.gain, 2.0);  // the entry's own default
  EXPECT_EQ(c.renames, (std::map<std::string, std::string>{{"wrist_r", "hand_r"}}));
  EXPECT_EQ(c.lists.at("/t"), (std::vector<std::string>{"a", "b"}));
  // Absent: the defaults.
  const Catalogue d = LoadParamsFile<Catalogue>(Write("named_empty.yaml", "renames: {}\n"));
  ASSERT_EQ(d.gains.size(), 1u);
  EXPECT_EQ(d.gains[0].first, "default");
  // An entry's unknown key and a wrong type are named with the entry.
  const std::string bad = Write("named_bad.yaml", "gains: {a: {gian: 1}, b: {gain: x}}\n");
  try {
    LoadParamsFile<Catalogue>(bad);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key 'gains.a.gian'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("key 'gains.b.gain': expected a finite number, got 'x'"), std::string::npos)
        << e.what();
  }
  // Described: the entries' names, then one entry's fields.
  const std::vector<ParamDoc> docs = DescribeParams(Catalogue{});
  ASSERT_GE(docs.size(), 4u);
  EXPECT_EQ(docs[0].key, "gains");
  EXPECT_EQ(docs[0].value, "{default}");
  EXPECT_EQ(docs[1].key, "gains.NAME.gain");
  EXPECT_EQ(docs[2].value, "{}");
}

TEST(Params, OverridesAreAppliedBeforeReadingAndCheckedLikeTheFile) {
  const std::string path = Write("over.yaml", "dt: 0.05\n");
  const Demo d = LoadParamsFile<Demo>(path, {{"dt", "0.2"}, {"inner.gain", "4"}});
  EXPECT_EQ(d.dt, 0.2);
  EXPECT_EQ(d.inner.gain, 4.0);
  EXPECT_EQ(LoadError(path, {{"dtt", "1"}}), path + ": unknown key 'dtt'");
  EXPECT_EQ(LoadError(path, {{"count", "0"}}), path + ": count must be >= 1");
}

TEST(Params, AServiceFileHandsOverridesToTheParameterFileItNames) {
  // --set svc.planner.dt=0.3 with `planner: p.yaml`, and into a default file.
  auto c = ConfigSection::FromString("svc:\n  planner: p.yaml\n", "/etc/iplan/svc.yaml");
  c.Override("svc.planner.dt", "0.3");
  c.Override("svc.planner.inner.gain", "5");
  auto d = ConfigSection::FromString("svc: {}\n", "/etc/iplan/svc.yaml");
  d.Override("svc.planner.dt", "0.4");
  d.Override("svc.planner.inner.gain", "6");
  std::string file;
  auto s = c.Section("svc");
  EXPECT_EQ(s.ReadParamsFile("planner", "default.yaml", &file),
            (Overrides{{"dt", "0.3"}, {"inner.gain", "5"}}));
  EXPECT_EQ(file, "/etc/iplan/p.yaml");
  EXPECT_NO_THROW(c.Finish());
  auto t = d.Section("svc");
  EXPECT_EQ(t.ReadParamsFile("planner", "default.yaml", &file), (Overrides{{"dt", "0.4"}, {"inner.gain", "6"}}));
  EXPECT_EQ(file, "/etc/iplan/default.yaml");
  EXPECT_NO_THROW(d.Finish());
  // Into a key that is no parameter file of the service: reported.
  auto e = ConfigSection::FromString("svc:\n  rate: 3\n", "svc.yaml");
  e.Override("svc.rate.x", "1");
  int rate = 0;
  e.Section("svc").Read("rate", &rate);
  EXPECT_THROW(e.Finish(), ConfigError);
}

TEST(Params, ReadParamsReportsValidateAsAProblemOfTheSection) {
  auto c = ConfigSection::FromString("svc:\n  dt: -1\n", "svc.yaml");
  Demo d;
  ReadParams(c.Section("svc"), &d);
  ASSERT_EQ(c.Problems().size(), 1u);
  EXPECT_EQ(c.Problems()[0], "svc.yaml: section 'svc': dt must be > 0");
}

TEST(Params, DescribesDefaultsWithDocsAsYamlText) {
  const std::vector<ParamDoc> docs = DescribeParams(Demo{});
  ASSERT_EQ(docs.size(), 8u);
  EXPECT_EQ(docs[0].key, "dt");
  EXPECT_EQ(docs[0].value, "0.1");
  EXPECT_EQ(docs[0].doc, "s; > 0");
  EXPECT_EQ(docs[2].value, "7");
  EXPECT_EQ(docs[3].value, "true");
  EXPECT_EQ(docs[4].value, "panda_link8");
  EXPECT_EQ(docs[5].value, "[0.0, 0.0, 0.5]");
  EXPECT_EQ(docs[6].value, "[[a, b]]");
  EXPECT_EQ(docs[7].key, "inner.gain");
  EXPECT_EQ(docs[7].value, "2.0");
  EXPECT_EQ(ParamText(std::string("true")), "\"true\"");
  EXPECT_EQ(ParamText(std::string("1e3")), "\"1e3\"");
  EXPECT_EQ(ParamText(1e-4), "1e-04");  // shortest round-trip text
  EXPECT_EQ(ParamsMarkdownTable({docs[0]}), "| key | default | meaning |\n|---|---|---|\n| `dt` | `0.1` | s; > 0 |\n");
  // Every described default reads back as the same value.
  std::string yaml;
  for (const ParamDoc& p : docs) {
    const std::size_t dot = p.key.find('.');
    yaml += dot == std::string::npos ? p.key + ": " + p.value + "\n"
                                     : p.key.substr(0, dot) + ": {" + p.key.substr(dot + 1) + ": " + p.value + "}\n";
  }
  const Demo back = LoadParamsFile<Demo>(Write("back.yaml", yaml));
  EXPECT_EQ(back.offset, Demo{}.offset);
  EXPECT_EQ(back.pairs, Demo{}.pairs);
  EXPECT_EQ(back.inner.gain, Demo{}.inner.gain);
}

}  // namespace
}  // namespace iplan::core
