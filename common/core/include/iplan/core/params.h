// Parameters declared once. A parameter struct lists its fields in one
// member template, in the style of Drake's Serialize(Archive*):
//
//   struct ReplannerParams {
//     double planning_step = 0.1;
//     template <class Archive>
//     void Serialize(Archive* a) {
//       a->Visit(IPLAN_NVP(planning_step, "s; one planning cycle per step"));
//     }
//     std::string Validate() const;  // every range, "" when valid
//   };
//
// From that one list come: strict loading (ReadParams: unknown keys, wrong
// types and Validate() failures are errors naming the file and the key),
// --set overrides (they are applied to the YAML before reading, so they reach
// every struct read this way, library parameter files included), and the
// documented defaults (DescribeParams: key, default value, doc line; `iplan
// config defaults` prints them). Ranges live only in Validate().
//
// Field types: bool, int, std::uint64_t, double, std::string,
// std::vector<double>, std::vector<std::string>, std::array<double, N>,
// std::vector<std::pair<std::string, std::string>> (a list of [a, b]),
// std::optional of those (absent: nullopt), and
// any struct with its own Serialize (read from a nested mapping),
// std::vector of such structs (a list of mappings), core::Named<T> of such
// structs (a mapping of name: struct, in the file's order) and
// std::map<std::string, V> of a value type above (a mapping). IPLAN_NVP_REQUIRED
// marks a key a file must give.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "iplan/core/config.h"
#include "iplan/core/name_value.h"

namespace iplan::core {

class ParamsReader;

/// A mapping of name: struct (each struct read from its own mapping), in the
/// file's order; present in a file, it replaces the default entries.
template <class T>
using Named = std::vector<std::pair<std::string, T>>;

/// True for structs that declare their fields with Serialize.
template <class T, class = void>
struct HasSerialize : std::false_type {};
template <class T>
struct HasSerialize<T, std::void_t<decltype(std::declval<T&>().Serialize(std::declval<ParamsReader*>()))>>
    : std::true_type {};

/// Reads fields from a ConfigSection; problems are recorded in it (its
/// Finish() reports them with the unknown keys).
class ParamsReader {
 public:
  explicit ParamsReader(ConfigSection section) : section_(std::move(section)) {}

  template <class T>
  void Visit(const NameValue<T>& nv) {
    if (nv.required && !section_.Has(nv.name)) {
      section_.AddError(nv.name, "is required but missing");
      return;
    }
    if constexpr (HasSerialize<T>::value) {
      ParamsReader nested(section_.Section(nv.name));
      nv.value->Serialize(&nested);
    } else {
      ReadValue(nv.name, nv.value);
    }
  }

 private:
  template <class T>
  void ReadValue(const char* key, T* value) {
    section_.Read(key, value);
  }
  // Absent: nullopt (or the default); present: the value.
  template <class T>
  void ReadValue(const char* key, std::optional<T>* value) {
    if (!section_.Has(key)) return;
    const std::size_t before = section_.Problems().size();
    T v{};
    ReadValue(key, &v);
    if (section_.Problems().size() == before) *value = v;
  }
  // A list of mappings, one struct each; present, it replaces the default list.
  template <class T, class = std::enable_if_t<HasSerialize<T>::value>>
  void ReadValue(const char* key, std::vector<T>* value) {
    if (!section_.Has(key)) {
      section_.Elements(key);  // marks it read
      return;
    }
    std::vector<T> out;
    for (ConfigSection& element : section_.Elements(key)) {
      T item;
      ParamsReader nested(element);
      item.Serialize(&nested);
      out.push_back(std::move(item));
    }
    *value = std::move(out);
  }
  // A mapping of name: struct; present, it replaces the default entries.
  template <class T, class = std::enable_if_t<HasSerialize<T>::value>>
  void ReadValue(const char* key, Named<T>* value) {
    ConfigSection named = section_.Section(key);
    if (!section_.Has(key)) return;
    Named<T> out;
    for (const std::string& name : named.Keys()) {
      T item;
      ParamsReader nested(named.Section(name));
      item.Serialize(&nested);
      out.emplace_back(name, std::move(item));
    }
    *value = std::move(out);
  }
  // A mapping of name: value; present, it replaces the default.
  template <class V>
  void ReadValue(const char* key, std::map<std::string, V>* value) {
    ConfigSection m = section_.Section(key);
    if (!section_.Has(key)) return;
    std::map<std::string, V> out;
    for (const std::string& name : m.Keys()) {
      V v{};
      if (m.Read(name, &v)) out[name] = v;
    }
    *value = std::move(out);
  }
  template <std::size_t N>
  void ReadValue(const char* key, std::array<double, N>* value) {
    std::vector<double> v(value->begin(), value->end());
    if (!section_.Read(key, &v)) return;
    if (v.size() != N) {
      section_.AddError(key, "expected " + std::to_string(N) + " numbers, got " + std::to_string(v.size()));
      return;
    }
    for (std::size_t i = 0; i < N; ++i) (*value)[i] = v[i];
  }

  ConfigSection section_;
};

/// Reads `*params` from `section` and, when every key read cleanly, records
/// params->Validate()'s reason (if any) as a problem of the section. The
/// caller's Finish() throws the ConfigError listing them all.
template <class P>
void ReadParams(ConfigSection section, P* params) {
  const std::size_t before = section.Problems().size();
  ParamsReader reader(section);
  params->Serialize(&reader);
  if (section.Problems().size() != before) return;
  if (const std::string why = params->Validate(); !why.empty()) section.AddProblem(why);
}

/// A whole parameter file: Load (by default an empty file means all
/// defaults, as it always has for the planner's file), the overrides, ReadParams, Finish. Throws
/// ConfigError ("FILE: unknown key 'x'", "FILE: key 'dt': expected a finite
/// number, got 'abc'", "FILE: dt must be > 0, got 0", ...).
template <class P>
P LoadParamsFile(const std::string& path, const Overrides& overrides = {},
                 ConfigSection::EmptyFile empty = ConfigSection::EmptyFile::kAllDefaults) {
  ConfigSection file = ConfigSection::Load(path, empty);
  for (const auto& [key, yaml] : overrides) file.Override(key, yaml);
  P params;
  ReadParams(file, &params);
  file.Finish();
  return params;
}

/// One documented parameter: dotted key, default value as YAML text, doc.
struct ParamDoc {
  std::string key;
  std::string value;
  std::string doc;
};

/// Formats values as YAML text (shortest round-trip form for doubles).
std::string ParamText(bool v);
std::string ParamText(int v);
std::string ParamText(std::uint64_t v);
std::string ParamText(double v);
std::string ParamText(const std::string& v);
std::string ParamText(const std::vector<double>& v);
std::string ParamText(const std::vector<std::string>& v);
std::string ParamText(const std::vector<std::pair<std::string, std::string>>& v);
template <class V>
std::string ParamText(const std::map<std::string, V>& v) {
  std::string s = "{";
  for (const auto& [k, x] : v) s += (s.size() > 1 ? ", " : "") + ParamText(k) + ": " + ParamText(x);
  return s + "}";
}
template <std::size_t N>
std::string ParamText(const std::array<double, N>& v) {
  return ParamText(std::vector<double>(v.begin(), v.end()));
}
template <class T>
std::string ParamText(const std::optional<T>& v) {
  return v ? ParamText(*v) : std::string("(none)");
}

/// Lists every field of a params struct with its current value.
class ParamsDescriber {
 public:
  explicit ParamsDescriber(std::string prefix = "") : prefix_(std::move(prefix)) {}

  template <class T>
  void Visit(const NameValue<T>& nv) {
    const std::string key = prefix_.empty() ? nv.name : prefix_ + "." + nv.name;
    if constexpr (HasSerialize<T>::value) {
      Nested(key, *nv.value);
    } else if constexpr (IsListOfStructs<T>::value) {
      docs_.push_back({key, nv.required ? "(required)" : ParamText(nv.value->size()) + " entries", nv.doc});
      Nested(key + "[]", typename T::value_type{});  // the fields of one entry
    } else if constexpr (IsNamedStructs<T>::value) {
      std::string names;
      for (const auto& [name, item] : *nv.value) names += (names.empty() ? "" : ", ") + name;
      docs_.push_back({key, nv.required ? "(required)" : "{" + names + "}", nv.doc});
      Nested(key + ".NAME", typename T::value_type::second_type{});  // the fields of one entry
    } else {
      docs_.push_back({key, nv.required ? "(required)" : ParamText(*nv.value), nv.doc});
    }
  }
  std::vector<ParamDoc>& docs() { return docs_; }

 private:
  template <class T>
  struct IsListOfStructs : std::false_type {};
  template <class T>
  struct IsListOfStructs<std::vector<T>> : HasSerialize<T> {};
  template <class T>
  struct IsNamedStructs : std::false_type {};
  template <class T>
  struct IsNamedStructs<std::vector<std::pair<std::string, T>>> : HasSerialize<T> {};
  template <class T>
  void Nested(const std::string& key, T value) {
    ParamsDescriber nested(key);
    value.Serialize(&nested);
    for (ParamDoc& d : nested.docs_) docs_.push_back(std::move(d));
  }

  std::string prefix_;
  std::vector<ParamDoc> docs_;
};

/// The fields of `params` (pass a default-constructed one for the defaults).
template <class P>
std::vector<ParamDoc> DescribeParams(P params) {
  ParamsDescriber d;
  params.Serialize(&d);
  return std::move(d.docs());
}

/// A Markdown table "| key | default | meaning |" of `docs`, one row each.
std::string ParamsMarkdownTable(const std::vector<ParamDoc>& docs);

/// "" when the Markdown file `doc_path` holds ParamsMarkdownTable(docs)
/// verbatim, else why not (with the table it should hold): keeps
/// docs/configuration.md true in the tests. Never throws.
std::string CheckDocumentedDefaults(const std::string& doc_path, const std::vector<ParamDoc>& docs);

}  // namespace iplan::core
