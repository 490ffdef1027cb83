// JSON Schema (draft 2020-12 subset: type, properties, items, bounds) of the
// JSON form of every message type (iplan/msg/json.h), built from the same
// field reflection. Foxglove and MCAP tools use it to describe JSON channels
// ("jsonschema" schema encoding). Non-finite numbers travel as the strings
// "nan", "inf", "-inf" (json.h), so a floating-point field admits them.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "iplan/msg/visit.h"

namespace iplan::msg {
namespace internal {

template <class T>
nlohmann::json ValueSchema() {
  if constexpr (kIsMessage<T>) {
    nlohmann::json props = nlohmann::json::object();
    nlohmann::json required = nlohmann::json::array();
    T probe{};
    FieldsOf<T>::Visit(
        [&](const char* name, const auto& f) {
          props[name] = ValueSchema<std::decay_t<decltype(f)>>();
          required.push_back(name);
        },
        probe);
    return {{"type", "object"}, {"title", TypeName<T>::kDds}, {"properties", props}, {"required", required}};
  } else if constexpr (IsVector<T>::value) {
    return {{"type", "array"}, {"items", ValueSchema<typename T::value_type>()}};
  } else if constexpr (IsArray<T>::value) {
    const auto n = std::tuple_size<T>::value;
    return {{"type", "array"}, {"items", ValueSchema<typename T::value_type>()}, {"minItems", n}, {"maxItems", n}};
  } else if constexpr (std::is_floating_point_v<T>) {
    return {{"oneOf", {{{"type", "number"}}, {{"enum", {"nan", "inf", "-inf"}}}}}};
  } else if constexpr (std::is_same_v<T, bool>) {
    return {{"type", "boolean"}};
  } else if constexpr (std::is_same_v<T, std::string>) {
    return {{"type", "string"}};
  } else {
    static_assert(std::is_integral_v<T>, "unsupported field type");
    return {{"type", "integer"},
            {"minimum", static_cast<long long>(std::numeric_limits<T>::min())},
            {"maximum", static_cast<unsigned long long>(std::numeric_limits<T>::max())}};
  }
}

}  // namespace internal

/// The JSON Schema of ToJson(T). Allocates; call once per type and keep it.
template <class T>
nlohmann::json JsonSchema() {
  nlohmann::json s = internal::ValueSchema<T>();
  s["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  return s;
}

}  // namespace iplan::msg
