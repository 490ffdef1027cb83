// Messages the multi-process tests build again and again.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/msg/types.h"

namespace iplan::testing {

/// A skeleton in the cell frame: joint j named names[j] at positions[j]
/// (m, world), every confidence 1.
inline msg::HumanSkeleton SkeletonMessage(const msg::Time& stamp, const std::vector<std::string>& names,
                                          const std::vector<Eigen::Vector3d>& positions, uint32_t body_id = 0) {
  msg::HumanSkeleton s;
  s.header.stamp = stamp;
  s.header.frame_id = "world";
  s.body_id = body_id;
  s.confidence = 1;
  for (std::size_t j = 0; j < positions.size(); ++j) {
    msg::HumanJoint h;
    h.name = names[j];
    h.position = {positions[j].x(), positions[j].y(), positions[j].z()};
    h.confidence = 1;
    s.joints.push_back(h);
  }
  return s;
}

}  // namespace iplan::testing
