#include "iplan/framework/config.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "iplan/core/yaml.h"

namespace iplan::framework {
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

ConfigSection ConfigSection::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open the configuration file");
  std::stringstream ss;
  ss << in.rdbuf();
  return FromString(ss.str(), path);
}

ConfigSection ConfigSection::FromString(const std::string& yaml, const std::string& name) {
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
  if (state->root.IsNull()) throw ConfigError(name + ": the file is empty");
  if (const std::string dup = core::FindDuplicateKey(state->root); !dup.empty()) throw ConfigError(name + ": " + dup);
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

void ConfigSection::Override(const std::string& dotted_key, const std::string& yaml) {
  YAML::Node value;
  try {
    value = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError("--set " + dotted_key + "=" + yaml + ": the value is not valid YAML: " + e.msg);
  }
  if (const std::string dup = core::FindDuplicateKey(value); !dup.empty()) {
    throw ConfigError("--set " + dotted_key + "=" + yaml + ": " + dup);
  }
  std::vector<std::string> parts;
  for (size_t b = 0;;) {
    const size_t e = dotted_key.find('.', b);
    parts.push_back(dotted_key.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  YAML::Node n = node_;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].empty()) throw ConfigError("--set " + dotted_key + ": empty key");
    if (!n.IsMap() && !n.IsNull()) throw ConfigError("--set " + dotted_key + ": '" + parts[i] + "' is not inside a mapping");
    if (i + 1 == parts.size()) {
      n[parts[i]] = value;
    } else {
      YAML::Node next = n[parts[i]];
      if (!next.IsDefined() || next.IsNull()) {
        n[parts[i]] = YAML::Node(YAML::NodeType::Map);
        next = n[parts[i]];
      }
      n.reset(next);
    }
  }
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
template bool ConfigSection::Read(const std::string&, double*, Check<double>);
template bool ConfigSection::Read(const std::string&, std::string*, Check<std::string>);
template bool ConfigSection::Read(const std::string&, std::vector<double>*, Check<std::vector<double>>);
template bool ConfigSection::Read(const std::string&, std::vector<std::string>*, Check<std::vector<std::string>>);
template bool ConfigSection::Require(const std::string&, bool*, Check<bool>);
template bool ConfigSection::Require(const std::string&, int*, Check<int>);
template bool ConfigSection::Require(const std::string&, double*, Check<double>);
template bool ConfigSection::Require(const std::string&, std::string*, Check<std::string>);
template bool ConfigSection::Require(const std::string&, std::vector<double>*, Check<std::vector<double>>);
template bool ConfigSection::Require(const std::string&, std::vector<std::string>*, Check<std::vector<std::string>>);

void ConfigSection::Finish() const {
  std::vector<std::string> keys;
  CollectKeys(state_->root, "", &keys);
  std::vector<std::string> problems = state_->errors;
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

}  // namespace iplan::framework

namespace iplan::framework {

std::string ConfigSection::ResolvePath(const std::string& path) const {
  const std::filesystem::path p(path);
  if (path.empty() || p.is_absolute()) return path;
  return (std::filesystem::path(file()).parent_path() / p).lexically_normal().string();
}

}  // namespace iplan::framework
