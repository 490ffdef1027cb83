// Run-time table of every message type, for tools that choose a type by its
// DDS name (e.g. `iplan topic echo` on a discovered topic).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iplan::msg {

struct TypeEntry {
  const char* dds_name;  ///< e.g. "sensor_msgs::msg::dds_::JointState_"
  const char* cpp_name;  ///< e.g. "JointState"
  void* (*create)();     ///< new default message
  void (*destroy)(void*);
  nlohmann::json (*to_json)(const void*);
  void (*from_json)(const nlohmann::json&, void*);  ///< throws std::invalid_argument
  void (*randomize)(void*, uint64_t seed);          ///< FillRandom with a seeded generator
  std::optional<std::string> (*first_difference)(const void*, const void*);
  nlohmann::json (*json_schema)();  ///< JSON Schema of to_json's output (iplan/msg/json_schema.h)
};

/// Every generated type. Thread-safe.
const std::vector<TypeEntry>& AllTypes();

/// The entry with this DDS name or C++ name, or nullptr.
const TypeEntry* FindType(const std::string& name);

}  // namespace iplan::msg
