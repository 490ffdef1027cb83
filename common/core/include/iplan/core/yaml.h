// Strict YAML for every file loader. yaml-cpp keeps both pairs of a key
// written twice in one mapping, and operator[] silently returns the first:
// an edit that meant to replace a value (a second `rate_hz:` further down)
// would be ignored without a word. These helpers make that an error.
// Target iplan::yaml (the yaml-cpp dependency stays out of iplan::core).
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

namespace iplan::core {

/// The first key written twice in one mapping of `node`, at any depth
/// (mappings inside lists included), as "key 'a.list[2].b': appears twice
/// (lines 3 and 7)" (the lines only when the node came from a parser);
/// empty when there is none. Scalar keys are compared by their text, so
/// `a` and `"a"` are the same key. Thread-safe for distinct nodes; allocates.
std::string FindDuplicateKey(const YAML::Node& node);

/// YAML::LoadFile(path), strictly: throws std::runtime_error
/// "<path>: key 'a.b': appears twice (lines 3 and 7)" when FindDuplicateKey
/// finds one. A file that cannot be opened or parsed throws YAML::Exception
/// as YAML::LoadFile does, so each loader words that as before. An empty
/// file is a null node (whether that is allowed is the loader's decision).
YAML::Node LoadYamlFile(const std::string& path);

}  // namespace iplan::core
