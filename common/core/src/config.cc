#include "iplan/core/config.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "iplan/core/yaml.h"

namespace iplan::core {
namespace {

std::string Describe(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

bool ParseBool(const std::string& s, bool* out) {
  if (s == "true" || s == "True" || s == "TRUE") { *out = true; return true; }
  if (s == "false" || s == "False" || s == "FALSE") { *out = false; return true; }
  return false;
}

bool ParseDouble(const std::string& s, double* out) {
  if (s.empty()) return false;
  std::istringstream in(s);
  in.imbue(std::locale::classic());
  in >> *out;
  return in && in.peek() == std::char_traits<char>::eof() && std::isfinite(*out);
}

bool ParseU64(const std::string& s, std::uint64_t* out) {
  if (s.empty() || s[0] < '0' || s[0] > '9') return false;
  std::size_t pos = 0;
  try {
    const unsigned long long v = std::stoull(s, &pos, 10);
    if (pos != s.size()) return false;
    *out = static_cast<std::uint64_t>(v);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

bool ParseInt(const std::string& s, int* out) {
  if (s.empty()) return false;
  std::size_t pos = 0;
  try {
    const long v = std::stol(s, &pos, 10);
    if (pos != s.size() || v < INT32_MIN || v > INT32_MAX) return false;
    *out = static_cast<int>(v);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

void CollectKeys(const YAML::Node& n, const std::string& path, std::vector<std::string>* keys) {
  if (n.IsSequence()) {
    // Mappings inside lists: their keys are checked when the list was read
    // with Elements (Finish skips keys whose parent is not a section).
    for (std::size_t i = 0; i < n.size(); ++i) CollectKeys(n[i], path + "[" + std::to_string(i) + "]", keys);
    return;
  }
  if (!n.IsMap()) return;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::string k = it->first.Scalar();
    const std::string full = path.empty() ? k : path + "." + k;
    keys->push_back(full);
    CollectKeys(it->second, full, keys);
  }
}

}  // namespace

Check<std::string> OneOf(std::vector<std::string> allowed) {
  return [allowed](const std::string& v) {
    for (const auto& a : allowed) {
      if (a == v) return std::string();
    }
    std::string s = "must be one of:";
    for (const auto& a : allowed) s += " " + a;
    return s;
  };
}

std::pair<std::string, std::string> ParseOverride(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw ConfigError("--set " + text + ": expected KEY=VALUE");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

ConfigSection ConfigSection::Load(const std::string& path, EmptyFile empty) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open the configuration file");
  std::stringstream ss;
  ss << in.rdbuf();
  return FromString(ss.str(), path, empty);
}

ConfigSection ConfigSection::FromString(const std::string& yaml, const std::string& name, EmptyFile empty) {
  auto state = std::make_shared<State>();
  state->file = name;
  try {
    state->root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ": line " + std::to_string(e.mark.line + 1) + ", column " +
                      std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  // An empty file is a mistake (a truncated copy, a wrong path to an empty
  // file), not "all defaults": a service's keys live in its section. An
  // explicitly empty mapping ("{}") still means all defaults.
  if (state->root.IsNull() && empty == EmptyFile::kAllDefaults) state->root = YAML::Node(YAML::NodeType::Map);
  if (state->root.IsNull()) throw ConfigError(name + ": the file is empty");
  if (const std::string dup = FindDuplicateKey(state->root); !dup.empty()) throw ConfigError(name + ": " + dup);
  if (!state->root.IsMap()) throw ConfigError(name + ": the top level must be a mapping of keys");
  YAML::Node root = state->root;
  return ConfigSection(state, root, "");
}

void ConfigSection::Error(const std::string& key, const std::string& problem) {
  state_->errors.push_back(state_->file + ": key '" + Full(key) + "': " + problem);
}

void ConfigSection::AddError(const std::string& key, const std::string& problem) {
  state_->consumed.insert(Full(key));
  Error(key, problem);
}

bool ConfigSection::Has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

std::vector<std::string> ConfigSection::Keys() const {
  std::vector<std::string> keys;
  if (!node_.IsMap()) return keys;
  for (const auto& kv : node_) keys.push_back(kv.first.as<std::string>());
  return keys;
}

namespace {

std::vector<std::string> SplitDotted(const std::string& dotted) {
  std::vector<std::string> parts;
  for (std::size_t b = 0;;) {
    const std::size_t e = dotted.find('.', b);
    parts.push_back(dotted.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) return parts;
    b = e + 1;
  }
}

// The leaves of a mapping built by Override, as dotted keys and YAML text.
void Flatten(const YAML::Node& n, const std::string& prefix, Overrides* out) {
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::string k = prefix.empty() ? it->first.Scalar() : prefix + "." + it->first.Scalar();
    if (it->second.IsMap()) {
      Flatten(it->second, k, out);
    } else {
      out->emplace_back(k, YAML::Dump(it->second));
    }
  }
}

std::string JoinDotted(const std::vector<std::string>& parts, std::size_t from, std::size_t to) {
  std::string s;
  for (std::size_t i = from; i < to; ++i) s += (i == from ? "" : ".") + parts[i];
  return s;
}

}  // namespace

void ConfigSection::Override(const std::string& dotted_key, const std::string& yaml) {
  YAML::Node value;
  try {
    value = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError("--set " + dotted_key + "=" + yaml + ": the value is not valid YAML: " + e.msg);
  }
  if (const std::string dup = FindDuplicateKey(value); !dup.empty()) {
    throw ConfigError("--set " + dotted_key + "=" + yaml + ": " + dup);
  }
  const std::vector<std::string> parts = SplitDotted(dotted_key);
  for (const std::string& part : parts) {
    if (part.empty()) throw ConfigError("--set " + dotted_key + ": empty key");
  }
  YAML::Node n = node_;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (n.IsScalar() && i > 0) {
      // A key naming a parameter file: the rest of the path is inside it.
      state_->file_overrides.push_back(
          {Full(JoinDotted(parts, 0, i)), JoinDotted(parts, i, parts.size()), yaml, false});
      return;
    }
    if (!n.IsMap() && !n.IsNull()) throw ConfigError("--set " + dotted_key + ": '" + parts[i] + "' is not inside a mapping");
    if (i + 1 == parts.size()) {
      n[parts[i]] = value;
    } else {
      YAML::Node next = n[parts[i]];
      if (!next.IsDefined() || next.IsNull()) {
        n[parts[i]] = YAML::Node(YAML::NodeType::Map);
        next = n[parts[i]];
        state_->created.insert(Full(JoinDotted(parts, 0, i + 1)));
      }
      n.reset(next);
    }
  }
}

Overrides ConfigSection::ReadParamsFile(const std::string& key, const std::string& default_path, std::string* path) {
  const std::string full = Full(key);
  Overrides out;
  std::string file = default_path;
  if (Has(key) && node_[key].IsMap() && state_->created.count(full)) {
    // Only --set made this mapping: overrides into the default file.
    state_->consumed.insert(full);
    Flatten(node_[key], "", &out);
  } else {
    Read(key, &file);
  }
  *path = ResolvePath(file);
  for (FileOverride& o : state_->file_overrides) {
    if (o.file_key != full) continue;
    o.claimed = true;
    out.emplace_back(o.key, o.yaml);
  }
  return out;
}

void ConfigSection::AddProblem(const std::string& problem) {
  state_->errors.push_back(state_->file + ": " + (path_.empty() ? "" : "section '" + path_ + "': ") + problem);
}

ConfigSection ConfigSection::Section(const std::string& key) {
  state_->consumed.insert(Full(key));
  state_->sections.insert(Full(key));
  if (!Has(key)) return ConfigSection(state_, YAML::Node(YAML::NodeType::Map), Full(key));
  YAML::Node n = node_[key];
  if (!n.IsMap()) {
    Error(key, "expected a mapping, got " + Describe(n));
    return ConfigSection(state_, YAML::Node(YAML::NodeType::Map), Full(key));
  }
  return ConfigSection(state_, n, Full(key));
}

std::vector<ConfigSection> ConfigSection::Elements(const std::string& key) {
  state_->consumed.insert(Full(key));
  std::vector<ConfigSection> out;
  if (!Has(key)) return out;
  const YAML::Node list = node_[key];
  if (!list.IsSequence()) {
    Error(key, "expected a list, got " + Describe(list));
    return out;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string item = key + "[" + std::to_string(i) + "]";
    if (!list[i].IsMap()) {
      Error(item, "expected a mapping, got " + Describe(list[i]));
      continue;
    }
    state_->consumed.insert(Full(item));
    state_->sections.insert(Full(item));
    out.push_back(ConfigSection(state_, list[i], Full(item)));
  }
  return out;
}

template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, bool* v) {
  if (n.IsScalar() && ParseBool(n.Scalar(), v)) return true;
  Error(key, "expected true or false, got " + Describe(n));
  return false;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, int* v) {
  if (n.IsScalar() && ParseInt(n.Scalar(), v)) return true;
  Error(key, "expected an integer, got " + Describe(n));
  return false;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, std::uint64_t* v) {
  if (n.IsScalar() && ParseU64(n.Scalar(), v)) return true;
  Error(key, "expected an integer >= 0, got " + Describe(n));
  return false;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key,
                            std::vector<std::pair<std::string, std::string>>* v) {
  if (!n.IsSequence()) {
    Error(key, "expected a list of [a, b] pairs, got " + Describe(n));
    return false;
  }
  std::vector<std::pair<std::string, std::string>> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node& e = n[i];
    if (!e.IsSequence() || e.size() != 2 || !e[0].IsScalar() || !e[1].IsScalar()) {
      Error(key + "[" + std::to_string(i) + "]", "expected a pair [a, b] of strings, got " + Describe(e));
      return false;
    }
    out.emplace_back(e[0].Scalar(), e[1].Scalar());
  }
  *v = std::move(out);
  return true;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, double* v) {
  if (n.IsScalar() && ParseDouble(n.Scalar(), v)) return true;
  Error(key, "expected a finite number, got " + Describe(n));
  return false;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, std::string* v) {
  if (n.IsScalar()) {
    *v = n.Scalar();
    return true;
  }
  Error(key, "expected a string, got " + Describe(n));
  return false;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, std::vector<double>* v) {
  if (!n.IsSequence()) {
    Error(key, "expected a list of numbers, got " + Describe(n));
    return false;
  }
  std::vector<double> out(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar() || !ParseDouble(n[i].Scalar(), &out[i])) {
      Error(key + "[" + std::to_string(i) + "]", "expected a finite number, got " + Describe(n[i]));
      return false;
    }
  }
  *v = std::move(out);
  return true;
}
template <>
bool ConfigSection::Convert(const YAML::Node& n, const std::string& key, std::vector<std::string>* v) {
  if (!n.IsSequence()) {
    Error(key, "expected a list of strings, got " + Describe(n));
    return false;
  }
  std::vector<std::string> out(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) {
      Error(key + "[" + std::to_string(i) + "]", "expected a string, got " + Describe(n[i]));
      return false;
    }
    out[i] = n[i].Scalar();
  }
  *v = std::move(out);
  return true;
}

template <class T>
bool ConfigSection::Read(const std::string& key, T* value, Check<T> check) {
  state_->consumed.insert(Full(key));
  if (!Has(key)) return false;
  T tmp = *value;
  if (!Convert(node_[key], key, &tmp)) return false;
  if (check) {
    if (const std::string why = check(tmp); !why.empty()) {
      Error(key, why + " (got " + Describe(node_[key]) + ")");
      return false;
    }
  }
  *value = std::move(tmp);
  return true;
}

template <class T>
bool ConfigSection::Require(const std::string& key, T* value, Check<T> check) {
  if (!Has(key)) {
    state_->consumed.insert(Full(key));
    Error(key, "is required but missing");
    return false;
  }
  return Read(key, value, check);
}

template bool ConfigSection::Read(const std::string&, bool*, Check<bool>);
template bool ConfigSection::Read(const std::string&, int*, Check<int>);
template bool ConfigSection::Read(const std::string&, std::uint64_t*, Check<std::uint64_t>);
template bool ConfigSection::Read(const std::string&, std::vector<std::pair<std::string, std::string>>*,
                                  Check<std::vector<std::pair<std::string, std::string>>>);
template bool ConfigSection::Read(const std::string&, double*, Check<double>);
template bool ConfigSection::Read(const std::string&, std::string*, Check<std::string>);
template bool ConfigSection::Read(const std::string&, std::vector<double>*, Check<std::vector<double>>);
template bool ConfigSection::Read(const std::string&, std::vector<std::string>*, Check<std::vector<std::string>>);
template bool ConfigSection::Require(const std::string&, bool*, Check<bool>);
template bool ConfigSection::Require(const std::string&, int*, Check<int>);
template bool ConfigSection::Require(const std::string&, std::uint64_t*, Check<std::uint64_t>);
template bool ConfigSection::Require(const std::string&, double*, Check<double>);
template bool ConfigSection::Require(const std::string&, std::string*, Check<std::string>);
template bool ConfigSection::Require(const std::string&, std::vector<double>*, Check<std::vector<double>>);
template bool ConfigSection::Require(const std::string&, std::vector<std::string>*, Check<std::vector<std::string>>);

void ConfigSection::Finish() const {
  std::vector<std::string> keys;
  CollectKeys(state_->root, "", &keys);
  std::vector<std::string> problems = state_->errors;
  for (const FileOverride& o : state_->file_overrides) {
    if (o.claimed) continue;
    problems.push_back("--set " + o.file_key + "." + o.key + "=" + o.yaml + ": '" + o.file_key +
                       "' is a value, not a mapping or a parameter file");
  }
  for (const auto& k : keys) {
    if (state_->consumed.count(k)) continue;
    const std::size_t dot = k.rfind('.');
    if (dot != std::string::npos) {
      const std::string parent = k.substr(0, dot);
      // Under an unknown key (already reported) or under a key read as a
      // value (its type error is already reported): nothing more to say.
      if (!state_->sections.count(parent)) continue;
    }
    problems.push_back(state_->file + ": unknown key '" + k + "'");
  }
  if (problems.empty()) return;
  std::string msg;
  for (const auto& p : problems) msg += (msg.empty() ? "" : "\n") + p;
  throw ConfigError(msg);
}

}  // namespace iplan::core

namespace iplan::core {

std::string ConfigSection::ResolvePath(const std::string& path) const {
  const std::filesystem::path p(path);
  if (path.empty() || p.is_absolute()) return path;
  return (std::filesystem::path(file()).parent_path() / p).lexically_normal().string();
}

}  // namespace iplan::core
