#include "iplan/msg/type_table.h"

namespace iplan::msg {

const TypeEntry* FindType(const std::string& name) {
  for (const auto& e : AllTypes()) {
    if (name == e.dds_name || name == e.cpp_name) return &e;
  }
  return nullptr;
}

}  // namespace iplan::msg
