// IPLAN_NVP: the one line a parameter struct writes per field in its
// Serialize(Archive*) (see iplan/core/params.h for the archives and the
// loading, override and documentation they give). Header only, no YAML, so
// that a core's public header can declare its parameters.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace iplan::core {

/// --set overrides, in order: {dotted key, value as YAML text}; what a
/// parameter file's loader takes besides its path.
using Overrides = std::vector<std::pair<std::string, std::string>>;

/// One field: its YAML key, where it lives, a one-line doc (units first) and
/// whether a file must give it (else the default stays).
template <class T>
struct NameValue {
  const char* name;
  T* value;
  const char* doc;
  bool required;
};

template <class T>
NameValue<T> MakeNameValue(const char* name, T* value, const char* doc, bool required = false) {
  return NameValue<T>{name, value, doc, required};
}

}  // namespace iplan::core

/// `a->Visit(IPLAN_NVP(dt, "s; waypoint spacing"))`: the key is the field name.
#define IPLAN_NVP(field, doc) ::iplan::core::MakeNameValue(#field, &(field), doc)
/// The same for a key every file must give ("is required but missing").
#define IPLAN_NVP_REQUIRED(field, doc) ::iplan::core::MakeNameValue(#field, &(field), doc, true)
