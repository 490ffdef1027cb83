#include "iplan/collision/self_collision.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>

namespace iplan::collision {
namespace {

// The nearest ancestor of `link` that carries spheres (-1: none), passing
// links without geometry (fixed frames, flanges).
int GeometricParent(const RobotModel& model, const std::vector<char>& has_spheres, int link) {
  int l = link;
  while (true) {
    const int j = model.link_parent_joint[l];
    if (j < 0) return -1;
    l = model.joints[j].parent_link;
    if (has_spheres[l]) return l;
  }
}

// Surface distance (m) between spheres i and k at the poses in `data`.
double Gap(const RobotModel& model, const RobotData& data, int i, int k) {
  return (data.p_WS.col(i) - data.p_WS.col(k)).norm() - model.spheres[i].radius - model.spheres[k].radius;
}

}  // namespace

std::string SelfCollisionParams::Validate() const {
  if (samples < 1) return "samples must be >= 1";
  if (!(never_margin >= 0.0) || !std::isfinite(never_margin)) return "never_margin must be finite and >= 0";
  if (!(always_fraction > 0.0 && always_fraction <= 1.0)) return "always_fraction must be in (0, 1]";
  return "";
}

const char* ToString(SkipReason r) {
  switch (r) {
    case SkipReason::kAdjacent: return "adjacent";
    case SkipReason::kAlways: return "always";
    case SkipReason::kNever: return "never";
  }
  return "?";
}

SelfCollisionModel ComputeSelfCollision(const RobotModel& model, const SelfCollisionParams& params) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("SelfCollisionParams: " + why);
  const int links = static_cast<int>(model.link_names.size());
  std::vector<char> has_spheres(links, 0);
  for (const CollisionSphere& s : model.spheres) has_spheres[s.link] = 1;
  // Every pair of links with spheres, its sphere pairs, its statistics.
  struct Stats {
    int a, b;
    std::vector<std::pair<int, int>> spheres;
    double min_distance = std::numeric_limits<double>::infinity();
    int touching = 0;
  };
  std::vector<Stats> pairs;
  for (int a = 0; a < links; ++a)
    for (int b = a + 1; b < links; ++b)
      if (has_spheres[a] && has_spheres[b]) pairs.push_back({a, b, {}});
  for (Stats& p : pairs)
    for (std::size_t i = 0; i < model.spheres.size(); ++i)
      for (std::size_t k = 0; k < model.spheres.size(); ++k)
        if (model.spheres[i].link == p.a && model.spheres[k].link == p.b)
          p.spheres.emplace_back(static_cast<int>(i), static_cast<int>(k));

  std::mt19937_64 rng(params.seed);
  const Eigen::VectorXd lo = model.LowerLimits(), hi = model.UpperLimits();
  RobotData data(model);
  Eigen::VectorXd q(model.nq);
  for (int n = 0; n < params.samples; ++n) {
    for (int i = 0; i < model.nq; ++i) {
      std::uniform_real_distribution<double> u(std::isfinite(lo[i]) ? lo[i] : -M_PI, std::isfinite(hi[i]) ? hi[i] : M_PI);
      q[i] = u(rng);
    }
    CalcForwardKinematics(model, q, &data);
    for (Stats& p : pairs) {
      double d = std::numeric_limits<double>::infinity();
      for (const auto& [i, k] : p.spheres) d = std::min(d, Gap(model, data, i, k));
      p.min_distance = std::min(p.min_distance, d);
      if (d < 0.0) ++p.touching;
    }
  }
  SelfCollisionModel out;
  for (const Stats& p : pairs) {
    const bool adjacent = GeometricParent(model, has_spheres, p.b) == p.a || GeometricParent(model, has_spheres, p.a) == p.b;
    std::optional<SkipReason> skip;
    if (adjacent) skip = SkipReason::kAdjacent;
    else if (p.touching >= params.always_fraction * params.samples) skip = SkipReason::kAlways;
    else if (p.min_distance > params.never_margin) skip = SkipReason::kNever;
    if (skip) {
      out.skipped.push_back({p.a, p.b, *skip, p.min_distance});
      continue;
    }
    out.checked.emplace_back(p.a, p.b);
    out.sphere_pairs.insert(out.sphere_pairs.end(), p.spheres.begin(), p.spheres.end());
  }
  return out;
}

double SelfDistance(const RobotModel& model, const SelfCollisionModel& self, const RobotData& data) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& [i, k] : self.sphere_pairs) d = std::min(d, Gap(model, data, i, k));
  return d;
}

}  // namespace iplan::collision
