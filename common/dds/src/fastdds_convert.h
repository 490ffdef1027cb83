// fastddsgen classes and the conversions to them (generated entries). Not on
// the data path (see fastdds_plain_type.h): used by the raw-vendor side of
// dds_latency_bench, fastdds_serialize_bench and fastdds_plain_type_test.
#pragma once

#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

#include "iplan/msg/types.h"
#include "iplan/msg/visit.h"

namespace iplan::dds::fastdds_gen {

struct FastTypeOps {
  const char* dds_name = nullptr;
  eprosima::fastdds::dds::TopicDataType* (*make_pubsub_type)() = nullptr;
  void* (*new_vendor)() = nullptr;
  void (*delete_vendor)(void*) = nullptr;
  void (*to_vendor)(const void* plain, void* vendor) = nullptr;
  /// May move data out of `vendor`.
  void (*from_vendor)(void* vendor, void* plain) = nullptr;
};

const std::vector<FastTypeOps>& AllFastTypes();

}  // namespace iplan::dds::fastdds_gen
