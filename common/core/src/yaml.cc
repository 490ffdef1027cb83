#include "iplan/core/yaml.h"

#include <map>
#include <stdexcept>

namespace iplan::core {
namespace {

std::string KeyText(const YAML::Node& key) { return key.IsScalar() ? key.Scalar() : YAML::Dump(key); }

// Depth first, in file order, so the reported key is the first one a reader meets.
std::string Find(const YAML::Node& node, const std::string& where) {
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (std::string dup = Find(node[i], where + "[" + std::to_string(i) + "]"); !dup.empty()) return dup;
    }
    return "";
  }
  if (!node.IsMap()) return "";
  std::map<std::string, YAML::Mark> seen;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = KeyText(it->first);
    const std::string full = where.empty() ? key : where + "." + key;
    const YAML::Mark mark = it->first.Mark();
    const auto [first, inserted] = seen.emplace(key, mark);
    if (!inserted) {
      std::string msg = "key '" + full + "': appears twice";
      if (!first->second.is_null() && !mark.is_null()) {
        msg += " (lines " + std::to_string(first->second.line + 1) + " and " + std::to_string(mark.line + 1) + ")";
      }
      return msg;
    }
    if (std::string dup = Find(it->second, full); !dup.empty()) return dup;
  }
  return "";
}

}  // namespace

std::string FindDuplicateKey(const YAML::Node& node) { return Find(node, ""); }

YAML::Node LoadYamlFile(const std::string& path) {
  YAML::Node root = YAML::LoadFile(path);
  if (const std::string dup = FindDuplicateKey(root); !dup.empty()) throw std::runtime_error(path + ": " + dup);
  return root;
}

}  // namespace iplan::core
