// Type support table for the Cyclone DDS backend (generated entries).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <dds/dds.h>

#include "iplan/msg/types.h"
#include "iplan/msg/visit.h"

namespace iplan::dds::cyclone_gen {

/// Scratch memory for one write: the C struct points into the plain message
/// where it can (strings, primitive sequences) and into the arena elsewhere.
class Arena {
 public:
  template <class T>
  T* Alloc(std::size_t n) {
    if (n == 0) return nullptr;
    blocks_.emplace_back(new std::max_align_t[(n * sizeof(T) + sizeof(std::max_align_t) - 1) /
                                              sizeof(std::max_align_t)]());
    return reinterpret_cast<T*>(blocks_.back().get());
  }
  void Clear() { blocks_.clear(); }

 private:
  std::vector<std::unique_ptr<std::max_align_t[]>> blocks_;
};

struct CycloneTypeOps {
  const char* dds_name = nullptr;
  const dds_topic_descriptor_t* descriptor = nullptr;
  std::size_t vendor_size = 0;
  /// Fills the zeroed C struct `vendor`; it borrows from `plain` and `arena`.
  void (*to_vendor)(const void* plain, void* vendor, Arena& arena) = nullptr;
  void (*from_vendor)(const void* vendor, void* plain) = nullptr;
};

const std::vector<CycloneTypeOps>& AllCycloneTypes();

}  // namespace iplan::dds::cyclone_gen
