// Strict YAML configuration. A service reads its keys through ConfigSection;
// every key it does not read, every value of the wrong type and every value
// that fails its check is an error naming the file and the key path.
//
//   ConfigSection c = ConfigSection::Load("config/perception.yaml");
//   ConfigSection p = c.Section("perception");
//   p.Read("rate_hz", &params.rate_hz, Positive<double>());
//   c.Finish();   // throws ConfigError listing every problem
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "iplan/core/name_value.h"

namespace iplan::core {

/// Thrown by ConfigSection::Finish and Load; what() lists every problem, one
/// per line, each "FILE: key 'a.b': problem".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A check returns "" when the value is acceptable, else the reason.
template <class T>
using Check = std::function<std::string(const T&)>;

template <class T>
Check<T> Positive() {
  return [](const T& v) { return v > T(0) ? std::string() : std::string("must be > 0"); };
}
template <class T>
Check<T> NonNegative() {
  return [](const T& v) { return v >= T(0) ? std::string() : std::string("must be >= 0"); };
}
template <class T>
Check<T> InRange(T lo, T hi) {
  return [lo, hi](const T& v) {
    return (v >= lo && v <= hi) ? std::string()
                                : "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  };
}
Check<std::string> OneOf(std::vector<std::string> allowed);

/// Splits "KEY=VALUE" (the --set syntax). Throws ConfigError
/// "--set TEXT: expected KEY=VALUE" when there is no '=' or no key.
std::pair<std::string, std::string> ParseOverride(const std::string& text);

class ConfigSection {
 public:
  /// Loads a YAML file. Throws ConfigError when it cannot be read or parsed
  /// (with the line and column), is empty (nothing but comments or a null:
  /// "FILE: the file is empty"; "{}" is an empty mapping and fine), has a key
  /// twice in one mapping at any depth ("FILE: key 'a.b': appears twice
  /// (lines 2 and 5)") or its top level is not a mapping.
  /// With EmptyFile::kAllDefaults an empty file reads as "{}" instead (the
  /// library parameter files, where an empty file has always meant defaults).
  enum class EmptyFile { kError, kAllDefaults };
  static ConfigSection Load(const std::string& path, EmptyFile empty = EmptyFile::kError);
  /// From YAML text (tests); `name` stands for the file in messages.
  static ConfigSection FromString(const std::string& yaml, const std::string& name,
                                  EmptyFile empty = EmptyFile::kError);

  /// Reads an optional key: absent keeps `*value` (the default). Supported
  /// types: bool, int, std::uint64_t, double, std::string,
  /// std::vector<double>, std::vector<std::string> and
  /// std::vector<std::pair<std::string, std::string>> (a list of [a, b]).
  /// Returns true when the key was present and valid.
  template <class T>
  bool Read(const std::string& key, T* value, Check<T> check = nullptr);
  /// Like Read, but an absent key is an error.
  template <class T>
  bool Require(const std::string& key, T* value, Check<T> check = nullptr);
  /// A nested mapping (empty when absent). Its keys are checked by Finish().
  ConfigSection Section(const std::string& key);
  /// The mappings of a list (none when absent), as sections named
  /// "key[0]", "key[1]", ...; their keys are checked by Finish(). An element
  /// that is not a mapping, or a value that is not a list, is an error.
  std::vector<ConfigSection> Elements(const std::string& key);
  /// True when the key is present.
  bool Has(const std::string& key) const;
  /// The keys of this mapping, in file order.
  std::vector<std::string> Keys() const;
  /// Overrides one value before it is read: `dotted_key` is a path of
  /// mapping keys from this section (e.g. "supervisor.max_episodes"), `yaml`
  /// the new value as YAML text ("3", "[1, 2]", "true"). Missing mappings on
  /// the path are created. A path that runs through a scalar (e.g.
  /// "trajopt.planner.dt" with `planner: planner.yaml`) is kept for the
  /// reader of that parameter file (ReadParamsFile). Throws ConfigError when
  /// `yaml` does not parse or has a key twice, or a key on the path is empty
  /// or runs through a list.
  void Override(const std::string& dotted_key, const std::string& yaml);
  /// Records a problem found by the caller (cross-field checks).
  void AddError(const std::string& key, const std::string& problem);
  /// Records a problem of this section as a whole, e.g. a Validate() reason
  /// that names its own fields: "FILE: problem" at the top level, else
  /// "FILE: section 'a.b': problem".
  void AddProblem(const std::string& problem);
  /// Reads the key naming a parameter file (a path, resolved as ResolvePath
  /// does; absent: `default_path`, resolved likewise) into `*path`, and
  /// returns the overrides given for keys inside that file: Override("a.f.dt",
  /// "3") with `a.f: planner.yaml` yields {"dt", "3"} for Section("a") ->
  /// ReadParamsFile("f", ...). Overrides into a file no reader claims are
  /// reported by Finish().
  Overrides ReadParamsFile(const std::string& key, const std::string& default_path, std::string* path);
  /// Throws ConfigError if any key anywhere in the file was not read, or any
  /// Read/Require/AddError recorded a problem.
  void Finish() const;
  /// The problems recorded so far by Read/Require/AddError (not the unread
  /// keys): for tools that read only part of a service's file.
  const std::vector<std::string>& Problems() const { return state_->errors; }
  const std::string& file() const { return state_->file; }
  /// `path` as written in this file, resolved the way every iplan config
  /// documents it: relative paths are relative to the folder of file();
  /// absolute and empty paths are returned unchanged.
  std::string ResolvePath(const std::string& path) const;

 private:
  struct FileOverride {
    std::string file_key;  // full path of the key naming the file
    std::string key;       // dotted key inside that file
    std::string yaml;
    bool claimed = false;
  };
  struct State {
    std::string file;
    std::vector<FileOverride> file_overrides;
    std::set<std::string> created;   // mappings created by Override
    std::set<std::string> consumed;  // full key paths that were read
    std::set<std::string> sections;  // full key paths read as sections
    std::vector<std::string> errors;
    YAML::Node root;
  };
  ConfigSection(std::shared_ptr<State> state, YAML::Node node, std::string path)
      : state_(std::move(state)), node_(std::move(node)), path_(std::move(path)) {}
  std::string Full(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  void Error(const std::string& key, const std::string& problem);
  template <class T>
  bool Convert(const YAML::Node& n, const std::string& key, T* value);

  std::shared_ptr<State> state_;
  YAML::Node node_;
  std::string path_;
};

}  // namespace iplan::core
