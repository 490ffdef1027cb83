#include "obstacle_set.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace iplan::trajopt {

ObstacleSet::ObstacleSet(double timeout, double min_half_extent)
    : timeout_(timeout), min_half_extent_(min_half_extent) {
  if (!(timeout > 0)) throw std::invalid_argument("obstacle timeout must be > 0");
  if (!(min_half_extent > 0)) throw std::invalid_argument("obstacle min_half_extent must be > 0");
}

std::optional<std::string> ObstacleSet::Update(int64_t stamp_ns, const std::vector<ObstacleBox>& boxes, bool* changed,
                                               double tolerance) {
  if (changed) *changed = false;
  std::set<uint32_t> ids;
  for (const ObstacleBox& b : boxes) {
    const std::string which = "obstacle " + std::to_string(b.id);
    if (b.id == 0) return std::string("obstacle id 0");
    if (!ids.insert(b.id).second) return which + " appears twice";
    if (!b.centre.allFinite() || !b.half_extents.allFinite() || b.half_extents.minCoeff() < 0)
      return which + " has a non-finite or negative size";
    if (!b.orientation.coeffs().allFinite() || std::abs(b.orientation.norm() - 1.0) > 1e-3)
      return which + " has an orientation that is not a unit quaternion";
  }
  bool any = false;
  for (const ObstacleBox& b : boxes) {
    auto it = boxes_.find(b.id);
    if (it == boxes_.end()) {
      boxes_[b.id] = Seen{b, stamp_ns};
      any = true;
      continue;
    }
    Seen& s = it->second;
    // A turn moves a corner by about the angle times the box's radius.
    const double turn = s.box.orientation.angularDistance(b.orientation) * b.half_extents.norm();
    if ((s.box.centre - b.centre).cwiseAbs().maxCoeff() > tolerance ||
        (s.box.half_extents - b.half_extents).cwiseAbs().maxCoeff() > tolerance || turn > tolerance) {
      s.box = b;  // small jitter keeps the box the planner has, so it does not replan for noise
      any = true;
    }
    s.last_seen_ns = std::max(s.last_seen_ns, stamp_ns);
  }
  if (changed) *changed = any;
  return std::nullopt;
}

bool ObstacleSet::Expire(int64_t now_ns) {
  const int64_t timeout = static_cast<int64_t>(timeout_ * 1e9);
  bool removed = false;
  for (auto it = boxes_.begin(); it != boxes_.end();) {
    if (now_ns - it->second.last_seen_ns > timeout) {
      it = boxes_.erase(it);
      removed = true;
    } else {
      ++it;
    }
  }
  return removed;
}

std::vector<collision::SceneObject> ObstacleSet::SceneObjects() const {
  std::vector<collision::SceneObject> out;
  out.reserve(boxes_.size());
  for (const auto& [id, s] : boxes_) {
    collision::SceneObject o;
    o.name = "obstacle " + std::to_string(id);
    o.shape = collision::SceneObject::Shape::kBox;
    o.X_WO.translation() = s.box.centre;
    o.X_WO.linear() = s.box.orientation.normalized().toRotationMatrix();
    o.size = 2.0 * s.box.half_extents.cwiseMax(min_half_extent_);
    out.push_back(o);
  }
  return out;
}

}  // namespace iplan::trajopt
