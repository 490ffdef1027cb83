// The JSON Schema of every message type (iplan/msg/json_schema.h, advertised
// by the viewer and stored in recordings) describes what to_json writes:
// checked on seeded random messages of every type, field by field.
#include <gtest/gtest.h>

#include "iplan/msg/type_table.h"

namespace iplan::msg {
namespace {

// Where `v` does not fit `s` (the subset json_schema.h emits); "" when it fits.
std::string Misfit(const nlohmann::json& v, const nlohmann::json& s, const std::string& path) {
  if (s.contains("oneOf")) {  // floating point: a number or "nan", "inf", "-inf"
    return v.is_number() || (v.is_string() && (v == "nan" || v == "inf" || v == "-inf")) ? "" : path + ": not a number";
  }
  const std::string type = s.at("type");
  if (type == "object") {
    if (!v.is_object()) return path + ": not an object";
    if (v.size() != s.at("properties").size()) return path + ": field count differs";
    for (const auto& [k, sub] : s.at("properties").items()) {
      if (!v.contains(k)) return path + "." + k + ": missing";
      if (auto m = Misfit(v.at(k), sub, path + "." + k); !m.empty()) return m;
    }
    return "";
  }
  if (type == "array") {
    if (!v.is_array()) return path + ": not an array";
    if (s.contains("minItems") && v.size() != s.at("minItems").get<std::size_t>()) return path + ": wrong length";
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (auto m = Misfit(v[i], s.at("items"), path + "[" + std::to_string(i) + "]"); !m.empty()) return m;
    }
    return "";
  }
  if (type == "integer") {
    if (!v.is_number_integer()) return path + ": not an integer";
    if (v.is_number_unsigned() ? v.get<unsigned long long>() > s.at("maximum").get<unsigned long long>()
                               : v.get<long long>() < s.at("minimum").get<long long>()) {
      return path + ": out of range";
    }
    return "";
  }
  if (type == "string") return v.is_string() ? "" : path + ": not a string";
  if (type == "boolean") return v.is_boolean() ? "" : path + ": not a boolean";
  return path + ": unknown schema type " + type;
}

TEST(JsonSchema, DescribesEveryTypesJson) {
  ASSERT_FALSE(AllTypes().empty());
  for (const TypeEntry& t : AllTypes()) {
    const nlohmann::json schema = t.json_schema();
    EXPECT_EQ(schema.at("title"), t.dds_name);
    EXPECT_EQ(schema.at("required").size(), schema.at("properties").size()) << t.cpp_name;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      void* m = t.create();
      t.randomize(m, seed);
      const std::string misfit = Misfit(t.to_json(m), schema, t.cpp_name);
      t.destroy(m);
      EXPECT_EQ(misfit, "") << "seed " << seed;
    }
  }
}

TEST(JsonSchema, FixedArraysHaveTheirLength) {
  const nlohmann::json s = FindType("HumanJoint")->json_schema();
  EXPECT_EQ(s["properties"]["covariance"]["minItems"], 9);
  EXPECT_EQ(s["properties"]["covariance"]["maxItems"], 9);
  EXPECT_EQ(s["properties"]["name"]["type"], "string");
}

}  // namespace
}  // namespace iplan::msg
