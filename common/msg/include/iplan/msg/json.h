// JSON form of every message type (used by `iplan topic echo/pub` and tests).
// Non-finite numbers are written as the strings "nan", "inf" and "-inf" and
// read back from them, so malformed samples can be produced on purpose.
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "iplan/msg/visit.h"

namespace iplan::msg {
namespace internal {

template <class T>
nlohmann::json ValueToJson(const T& v) {
  if constexpr (kIsMessage<T>) {
    nlohmann::json j = nlohmann::json::object();
    FieldsOf<T>::Visit([&](const char* name, const auto& f) { j[name] = ValueToJson(f); }, v);
    return j;
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& e : v) j.push_back(ValueToJson(e));
    return j;
  } else if constexpr (std::is_floating_point_v<T>) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return v;
  } else {
    return v;
  }
}

template <class T>
void ValueFromJson(const nlohmann::json& j, const std::string& path, T* v) {
  if constexpr (kIsMessage<T>) {
    if (!j.is_object()) throw std::invalid_argument(path + ": expected an object");
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool known = false;
      FieldsOf<T>::Visit([&](const char* name, auto&) { known = known || it.key() == name; }, *v);
      if (!known) throw std::invalid_argument(path + ": unknown field '" + it.key() + "'");
    }
    FieldsOf<T>::Visit(
        [&](const char* name, auto& f) {
          if (j.contains(name)) ValueFromJson(j.at(name), path.empty() ? name : path + "." + name, &f);
        },
        *v);
  } else if constexpr (IsVector<T>::value) {
    if (!j.is_array()) throw std::invalid_argument(path + ": expected an array");
    v->resize(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
      ValueFromJson(j[i], path + "[" + std::to_string(i) + "]", &(*v)[i]);
    }
  } else if constexpr (IsArray<T>::value) {
    if (!j.is_array() || j.size() != v->size()) {
      throw std::invalid_argument(path + ": expected an array of " + std::to_string(v->size()));
    }
    for (std::size_t i = 0; i < j.size(); ++i) {
      ValueFromJson(j[i], path + "[" + std::to_string(i) + "]", &(*v)[i]);
    }
  } else if constexpr (std::is_floating_point_v<T>) {
    if (j.is_string()) {
      const std::string s = j.get<std::string>();
      if (s == "nan") *v = std::numeric_limits<T>::quiet_NaN();
      else if (s == "inf") *v = std::numeric_limits<T>::infinity();
      else if (s == "-inf") *v = -std::numeric_limits<T>::infinity();
      else throw std::invalid_argument(path + ": expected a number, got \"" + s + "\"");
    } else if (j.is_number()) {
      *v = j.get<T>();
    } else {
      throw std::invalid_argument(path + ": expected a number");
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!j.is_boolean()) throw std::invalid_argument(path + ": expected true or false");
    *v = j.get<bool>();
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!j.is_string()) throw std::invalid_argument(path + ": expected a string");
    *v = j.get<std::string>();
  } else {
    if (!j.is_number_integer()) throw std::invalid_argument(path + ": expected an integer");
    const auto x = j.get<long long>();
    if (x < static_cast<long long>(std::numeric_limits<T>::min()) ||
        (x > 0 && static_cast<unsigned long long>(x) > static_cast<unsigned long long>(std::numeric_limits<T>::max()))) {
      throw std::invalid_argument(path + ": " + std::to_string(x) + " is out of range");
    }
    *v = static_cast<T>(x);
  }
}

}  // namespace internal

/// JSON object with one member per field, in IDL order.
template <class T>
nlohmann::json ToJson(const T& m) {
  return internal::ValueToJson(m);
}

/// Reads `j` into `*m`. Fields absent from `j` keep their value; unknown
/// fields, wrong JSON types and out-of-range integers throw
/// std::invalid_argument naming the field path.
template <class T>
void FromJson(const nlohmann::json& j, T* m) {
  internal::ValueFromJson(j, std::string(), m);
}

}  // namespace iplan::msg
