#include "services/cloud/core/cluster_tracker.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace iplan::cloud_service {

std::string TrackerParams::Validate() const {
  if (static_frames < 1) return "static_frames must be >= 1, got " + std::to_string(static_frames);
  if (!(static_motion > 0 && std::isfinite(static_motion))) return "static_motion must be > 0 m";
  if (!(match_distance > 0 && std::isfinite(match_distance))) return "match_distance must be > 0 m";
  if (lost_frames < 0) return "lost_frames must be >= 0, got " + std::to_string(lost_frames);
  if (!(person_extent > 0 && std::isfinite(person_extent))) return "person_extent must be > 0 m";
  return "";
}

void AddToMean(const UprightBox& next, int count, UprightBox* mean) {
  if (count <= 0) {
    *mean = next;
    return;
  }
  constexpr double kQuarter = M_PI / 2;
  double turn = std::remainder(next.yaw - mean->yaw, 2 * M_PI);  // in [-pi, pi]
  const long quarters = std::lround(turn / kQuarter);
  turn -= static_cast<double>(quarters) * kQuarter;  // in [-pi/4, pi/4]
  Eigen::Vector3d half = next.half_extents;
  if (quarters % 2 != 0) std::swap(half.x(), half.y());
  const double w = 1.0 / (count + 1);
  mean->centre += w * (next.centre - mean->centre);
  mean->yaw = std::remainder(mean->yaw + w * turn, 2 * M_PI);
  mean->half_extents += w * (half - mean->half_extents);
}

ClusterTracker::ClusterTracker(const TrackerParams& params) : params_(params) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument(why);
}

bool ClusterTracker::InSettledBox(const Track& t, const ClusterObservation& o) const {
  return t.cls == TrackClass::kStatic && (o.box_min.array() >= t.mean_min.array() - params_.static_motion).all() &&
         (o.box_max.array() <= t.mean_max.array() + params_.static_motion).all();
}

void ClusterTracker::Observe(Track* t, const ClusterObservation& o) const {
  t->last = o;
  t->unseen = 0;
  const double edge = (o.box_max - o.box_min).maxCoeff();
  if (edge >= params_.person_extent) t->cls = TrackClass::kHuman;
  // A static obstacle seen only in part (the arm passing in front of it, a
  // hand over it): the visible box lies within the settled box, grown by
  // static_motion. Its centroid moved, the object did not: it stays static,
  // its box as settled.
  if (InSettledBox(*t, o)) return;
  if ((o.centroid - t->anchor).norm() > params_.static_motion) {
    // It moved: whatever moves in the cell is taken for a person (a box
    // being carried moves with a hand), for the rest of the track's life.
    if (t->still > 0 || t->cls == TrackClass::kStatic) t->cls = TrackClass::kHuman;
    t->anchor = o.centroid;
    t->still = 1;
    t->mean_min = o.box_min;
    t->mean_max = o.box_max;
    t->mean_box = o.box;
    return;
  }
  ++t->still;
  const double w = 1.0 / t->still;  // running mean of the box since it settled
  t->mean_min += w * (o.box_min - t->mean_min);
  t->mean_max += w * (o.box_max - t->mean_max);
  AddToMean(o.box, t->still - 1, &t->mean_box);
  if (t->cls == TrackClass::kPending && t->still >= params_.static_frames) t->cls = TrackClass::kStatic;
}

std::vector<int> ClusterTracker::Update(const std::vector<ClusterObservation>& clusters, int64_t stamp_ns) {
  // Greedy assignment, nearest pairs first.
  std::vector<std::tuple<double, int, int>> pairs;
  for (int c = 0; c < static_cast<int>(clusters.size()); ++c) {
    for (int k = 0; k < static_cast<int>(tracks_.size()); ++k) {
      const double d = (clusters[c].centroid - tracks_[k].last.centroid).norm();
      if (d <= params_.match_distance) pairs.emplace_back(d, c, k);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> track_of(clusters.size(), -1);
  std::vector<char> taken(tracks_.size(), 0);
  for (const auto& [d, c, k] : pairs) {
    if (track_of[c] >= 0 || taken[k]) continue;
    track_of[c] = k;
    taken[k] = 1;
  }
  for (std::size_t k = 0; k < tracks_.size(); ++k) {
    if (!taken[k]) ++tracks_[k].unseen;
  }
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    if (track_of[c] >= 0) {
      Observe(&tracks_[static_cast<std::size_t>(track_of[c])], clusters[c]);
      continue;
    }
    // A second piece of a static obstacle (the arm in front of it split it
    // in two; the other piece took the track): it is that obstacle, seen in
    // part, not something new. A new track would be pending, so human, and
    // its points would be judged at the ISO speed 0.8 m from the person.
    const auto piece_of = std::find_if(tracks_.begin(), tracks_.end(),
                                       [&](const Track& t) { return InSettledBox(t, clusters[c]); });
    if (piece_of != tracks_.end()) {
      piece_of->unseen = 0;
      track_of[c] = static_cast<int>(piece_of - tracks_.begin());
      continue;
    }
    Track t;
    t.id = next_id_++;
    t.first_seen_ns = stamp_ns;
    t.anchor = clusters[c].centroid;
    t.still = 0;
    t.unseen = 0;
    t.anchor += Eigen::Vector3d::Constant(1e9);  // forces "settles here" in Observe
    Observe(&t, clusters[c]);
    t.cls = t.cls == TrackClass::kHuman ? TrackClass::kHuman : TrackClass::kPending;
    tracks_.push_back(t);
    taken.push_back(1);
    track_of[c] = static_cast<int>(tracks_.size()) - 1;
  }
  // Drop tracks unseen for too long, keeping the indices handed out valid.
  std::vector<int> new_index(tracks_.size(), -1);
  std::vector<Track> kept;
  for (std::size_t k = 0; k < tracks_.size(); ++k) {
    if (tracks_[k].unseen > params_.lost_frames) continue;
    new_index[k] = static_cast<int>(kept.size());
    kept.push_back(tracks_[k]);
  }
  tracks_ = std::move(kept);
  for (int& k : track_of) k = new_index[static_cast<std::size_t>(k)];
  return track_of;
}

}  // namespace iplan::cloud_service
