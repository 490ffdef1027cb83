// Several people in the cell: the one place that keeps "the newest X per
// tracked body" (skeleton history, prediction) and combines per-person
// results into the cell's answer. Used by the collision-risk monitor and the
// replanner, so both keep, expire and combine people the same way.
//
//  - PerBody<T>: per body id (the skeleton's / prediction's body_id) one
//    value with the stamp it was last updated at. An update older than the
//    body's stamp is refused (out of order; equal stamps too), bodies whose
//    stamp is older than a timeout are dropped (Expire), and at most
//    max_bodies are kept (a further body is refused, not an old one evicted).
//  - UnionBound: P(contact with anyone) <= sum over persons of each person's
//    bound (METHOD 4 per person, Boole's inequality over persons), capped at 1.
//  The ISO/TS 15066 separation of the cell is the nearest person's: the
//  monitor searches every person's sphere pairs (risk_monitor.h).
//
// Stamps are ns since the epoch (wall clock). Not thread-safe.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>


namespace iplan::cell {

/// Body id of a tracked person (msg HumanSkeleton/HumanPrediction body_id).
using BodyId = std::uint32_t;

template <class T>
class PerBody {
 public:
  struct Entry {
    int64_t stamp_ns = 0;  ///< of the newest update
    T value{};
  };
  using Map = std::map<BodyId, Entry>;

  explicit PerBody(int max_bodies = 8) : max_bodies_(max_bodies) {}

  /// The body's value for an update at stamp_ns (created empty for a new
  /// body), its stamp set to stamp_ns; nullptr with *why set when refused:
  /// not newer than the body's stamp, or max_bodies already kept.
  T* Touch(BodyId id, int64_t stamp_ns, std::string* why) {
    auto it = bodies_.find(id);
    if (it == bodies_.end()) {
      if (static_cast<int>(bodies_.size()) >= max_bodies_) {
        *why = "already tracking " + std::to_string(bodies_.size()) + " bodies (max " + std::to_string(max_bodies_) +
               "); body " + std::to_string(id) + " ignored";
        return nullptr;
      }
      it = bodies_.emplace(id, Entry{}).first;
      it->second.stamp_ns = stamp_ns;
      return &it->second.value;
    }
    if (stamp_ns <= it->second.stamp_ns) {
      *why = "body " + std::to_string(id) + ": stamp " + std::to_string(stamp_ns) + " ns is not after its newest " +
             std::to_string(it->second.stamp_ns) + " ns (out of order)";
      return nullptr;
    }
    it->second.stamp_ns = stamp_ns;
    return &it->second.value;
  }

  /// Replaces the body's value when stamp_ns is newer (see Touch). Returns
  /// why it was refused.
  std::optional<std::string> Update(BodyId id, int64_t stamp_ns, T value) {
    std::string why;
    T* v = Touch(id, stamp_ns, &why);
    if (!v) return why;
    *v = std::move(value);
    return std::nullopt;
  }

  /// Drops bodies whose stamp is older than now_ns - max_age_ns; returns how many.
  int Expire(int64_t now_ns, int64_t max_age_ns) {
    int dropped = 0;
    for (auto it = bodies_.begin(); it != bodies_.end();) {
      if (now_ns - it->second.stamp_ns > max_age_ns) {
        it = bodies_.erase(it);
        ++dropped;
      } else {
        ++it;
      }
    }
    return dropped;
  }

  /// Bodies whose stamp is at most max_age_ns old at now_ns (not removed).
  int CountFresh(int64_t now_ns, int64_t max_age_ns) const {
    int n = 0;
    for (const auto& [id, e] : bodies_) n += now_ns - e.stamp_ns <= max_age_ns;
    return n;
  }

  const Entry* Find(BodyId id) const {
    const auto it = bodies_.find(id);
    return it == bodies_.end() ? nullptr : &it->second;
  }
  /// The newest stamp over all bodies (0 when none).
  int64_t NewestStamp() const {
    int64_t t = 0;
    for (const auto& [id, e] : bodies_) t = std::max(t, e.stamp_ns);
    return t;
  }
  bool empty() const { return bodies_.empty(); }
  int size() const { return static_cast<int>(bodies_.size()); }
  typename Map::const_iterator begin() const { return bodies_.begin(); }
  typename Map::const_iterator end() const { return bodies_.end(); }
  typename Map::iterator begin() { return bodies_.begin(); }
  typename Map::iterator end() { return bodies_.end(); }

 private:
  int max_bodies_;
  Map bodies_;
};

/// Upper bound of P(contact with any person) from each person's bound at the
/// same waypoint: min(1, sum). 0 for nobody.
double UnionBound(const std::vector<double>& per_person);

}  // namespace iplan::cell
