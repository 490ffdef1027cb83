#include "iplan/core/yaml.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

namespace iplan::core {
namespace {

TEST(Yaml, FindsAKeyWrittenTwiceAtAnyDepth) {
  EXPECT_EQ(FindDuplicateKey(YAML::Load("a: 1\nb: {c: 2}\nl: [{x: 1}, {x: 2}]\n")), "");
  EXPECT_EQ(FindDuplicateKey(YAML::Load("a: 1\nb: 2\na: 3\n")), "key 'a': appears twice (lines 1 and 3)");
  EXPECT_EQ(FindDuplicateKey(YAML::Load("svc:\n  rate_hz: 30\n  sub:\n    k: 1\n    \"k\": 2\n")),
            "key 'svc.sub.k': appears twice (lines 4 and 5)");
  EXPECT_EQ(FindDuplicateKey(YAML::Load("tasks:\n  - name: a\n  - name: b\n    goal: [1]\n    name: c\n")),
            "key 'tasks[1].name': appears twice (lines 3 and 5)");
  EXPECT_EQ(FindDuplicateKey(YAML::Load("{x: 1, x: 2}")), "key 'x': appears twice (lines 1 and 1)");
  EXPECT_EQ(FindDuplicateKey(YAML::Load("")), "");
  EXPECT_EQ(FindDuplicateKey(YAML::Load("[1, 2, 2]")), "");  // a list may repeat values
}

TEST(Yaml, LoadFileNamesTheFileAndTheKey) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("iplan-yaml-" + std::to_string(getpid()) + ".yaml")).string();
  std::ofstream(path) << "objects:\n  - name: table\n    xyz: [0, 0, 0]\n    xyz: [1, 0, 0]\n";
  try {
    LoadYamlFile(path);
    ADD_FAILURE() << "a duplicated key was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": key 'objects[0].xyz': appears twice (lines 3 and 4)");
  }
  std::ofstream(path, std::ios::trunc) << "objects: []\n";
  EXPECT_TRUE(LoadYamlFile(path)["objects"].IsSequence());
  std::filesystem::remove(path);
  EXPECT_THROW(LoadYamlFile(path), YAML::BadFile);
}

}  // namespace
}  // namespace iplan::core
