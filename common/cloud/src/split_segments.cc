#include "split_segments.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <unordered_map>

#include <Eigen/Eigenvalues>

namespace iplan::cloud::internal {
namespace {

// Border lengths between fragments of one geometric segment, by 4-neighbour
// pixel pairs.
std::unordered_map<std::uint64_t, int> Borders(int width, int height, const std::vector<int>& geometric,
                                               const std::vector<int>& fragments) {
  std::unordered_map<std::uint64_t, int> borders;
  auto add = [&](int i, int j) {
    const int a = fragments[i], b = fragments[j];
    if (a < 0 || b < 0 || a == b || geometric[i] != geometric[j]) return;
    ++borders[(static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b))];
  };
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const int i = r * width + c;
      if (c + 1 < width) add(i, i + 1);
      if (r + 1 < height) add(i, i + width);
    }
  return borders;
}

int Find(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// Centroid and unit normal (towards the sensor at the origin) of each
// region's points, by PCA.
void RegionPlanes(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& region, int regions,
                  std::vector<Eigen::Vector3f>* centre, std::vector<Eigen::Vector3f>* normal) {
  std::vector<Eigen::Vector3d> sum(regions, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> outer(regions, Eigen::Matrix3d::Zero());
  std::vector<int> n(regions, 0);
  for (std::size_t i = 0; i < region.size(); ++i) {
    const int k = region[i];
    if (k < 0) continue;
    const Eigen::Vector3d p = points[i].cast<double>();
    sum[k] += p;
    outer[k] += p * p.transpose();
    ++n[k];
  }
  centre->assign(regions, Eigen::Vector3f::Zero());
  normal->assign(regions, Eigen::Vector3f::Zero());
  for (int k = 0; k < regions; ++k) {
    if (n[k] < 3) continue;
    const Eigen::Vector3d c = sum[k] / n[k];
    const Eigen::Matrix3d cov = outer[k] / n[k] - c * c.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    Eigen::Vector3d v = eig.eigenvectors().col(0);  // smallest eigenvalue
    if (v.dot(c) > 0) v = -v;                        // towards the sensor
    (*centre)[k] = c.cast<float>();
    (*normal)[k] = v.cast<float>();
  }
}

// Whether two adjacent regions belong together, judged as LCCP (Stein et
// al., CVPR 2014) judges adjacent supervoxels: coplanar (normals within the
// flat angle and each centroid near the other's plane), or convex (normals
// opening away from each other along the line joining the centres by more
// than a small margin). Faces of one box meet convexly; a box and what
// stands on it meet concavely or in a step between parallel planes.
bool Belong(const Eigen::Vector3f& ca, const Eigen::Vector3f& na, const Eigen::Vector3f& cb,
            const Eigen::Vector3f& nb, const ConvexityParams& p) {
  const Eigen::Vector3f ab = cb - ca;
  if (na.dot(nb) >= p.flat_cos && std::abs(na.dot(ab)) < p.coplanar_distance &&
      std::abs(nb.dot(ab)) < p.coplanar_distance)
    return true;
  return (-ab).normalized().dot(na - nb) > p.convex_margin;
}

// Merges adjacent cores (owner ids) of one geometric segment whose
// connection is convex or flat; rewrites owner.
void MergeConvexCores(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& fragments,
                      const std::unordered_map<std::uint64_t, int>& borders, std::vector<int>* owner,
                      const ConvexityParams& convexity) {
  const int nf = static_cast<int>(owner->size());
  std::vector<int> region(fragments.size(), -1);
  for (std::size_t i = 0; i < fragments.size(); ++i)
    if (fragments[i] >= 0) region[i] = (*owner)[fragments[i]];
  std::vector<Eigen::Vector3f> centre, normal;
  RegionPlanes(points, region, nf, &centre, &normal);
  std::unordered_map<std::uint64_t, int> core_borders;
  for (const auto& [key, length] : borders) {
    const int a = (*owner)[key >> 32], b = (*owner)[key & 0xffffffffu];
    if (a < 0 || b < 0 || a == b) continue;
    core_borders[(static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b))] +=
        length;
  }
  std::vector<int> parent(nf);
  for (int f = 0; f < nf; ++f) parent[f] = f;
  for (const auto& [key, length] : core_borders) {
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    if (Belong(centre[a], normal[a], centre[b], normal[b], convexity))
      parent[Find(parent, a)] = Find(parent, b);
  }
  for (int f = 0; f < nf; ++f)
    if ((*owner)[f] >= 0) (*owner)[f] = Find(parent, (*owner)[f]);
}

}  // namespace

std::vector<int> SplitSegments(int width, int height, const std::vector<Eigen::Vector3f>& points,
                               const std::vector<int>& geometric, const std::vector<int>& fragments,
                               int min_core, const ConvexityParams& convexity) {
  int nf = 0, ng = 0;
  for (std::size_t i = 0; i < fragments.size(); ++i) {
    nf = std::max(nf, fragments[i] + 1);
    ng = std::max(ng, geometric[i] + 1);
  }
  std::vector<int> size(nf, 0), geo_of(nf, -1);
  for (std::size_t i = 0; i < fragments.size(); ++i)
    if (fragments[i] >= 0) {
      ++size[fragments[i]];
      geo_of[fragments[i]] = geometric[i];
    }
  std::vector<int> cores(ng, 0), largest(ng, -1);
  for (int f = 0; f < nf; ++f) {
    const int g = geo_of[f];
    if (g < 0) continue;
    if (size[f] >= min_core) ++cores[g];
    if (largest[g] < 0 || size[f] > size[largest[g]]) largest[g] = f;
  }
  // owner[f]: the final segment of fragment f (a fragment id), -1 = not yet.
  std::vector<int> owner(nf, -1);
  bool any_split = false;
  for (int f = 0; f < nf; ++f) {
    const int g = geo_of[f];
    if (g < 0) continue;
    if (cores[g] < 2) owner[f] = largest[g];
    else if (size[f] >= min_core) owner[f] = f;
    else any_split = true;
  }
  if (any_split) {
    const auto borders = Borders(width, height, geometric, fragments);
    for (int pass = 0; pass < 16; ++pass) {
      // best[f] = (border length, owner) of the assigned neighbour bordering f most.
      std::vector<std::pair<int, int>> best(nf, {0, -1});
      for (const auto& [key, length] : borders) {
        const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
        if (owner[a] < 0 && owner[b] >= 0 && length > best[a].first) best[a] = {length, owner[b]};
        if (owner[b] < 0 && owner[a] >= 0 && length > best[b].first) best[b] = {length, owner[a]};
      }
      bool changed = false;
      for (int f = 0; f < nf; ++f)
        if (owner[f] < 0 && best[f].second >= 0) {
          owner[f] = best[f].second;
          changed = true;
        }
      if (!changed) break;
    }
    // Cut off from every core: the largest core of its geometric segment.
    std::vector<int> largest_core(ng, -1);
    for (int f = 0; f < nf; ++f) {
      const int g = geo_of[f];
      if (g >= 0 && owner[f] == f && (largest_core[g] < 0 || size[f] > size[largest_core[g]])) largest_core[g] = f;
    }
    for (int f = 0; f < nf; ++f)
      if (owner[f] < 0 && geo_of[f] >= 0) owner[f] = largest_core[geo_of[f]];
    MergeConvexCores(points, fragments, borders, &owner, convexity);
  }
  std::vector<int> out(fragments.size(), -1);
  for (std::size_t i = 0; i < fragments.size(); ++i)
    if (fragments[i] >= 0) out[i] = owner[fragments[i]];
  return out;
}

}  // namespace iplan::cloud::internal
