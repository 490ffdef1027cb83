// Splitting geometric segments along concave creases,
// then merging back parts that belong together (internal).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace iplan::cloud::internal {

struct ConvexityParams {
  float flat_cos = 0.94f;            ///< cos of the largest angle between coplanar normals
  float coplanar_distance = 0.01f;   ///< metres from a centroid to the other region's plane
  float convex_margin = 0.1f;        ///< d . (n_a - n_b) above this is convex
};

/// Combines two labelings of one width x height image (-1 = no segment):
/// `geometric` (segments by 3D gaps) and `fragments` (the same with
/// concave creases also separating; every fragment lies inside one
/// geometric segment). A geometric segment holding at least two fragments of
/// `min_core` pixels or more is split into those cores: every smaller
/// fragment joins the core it borders most (through other small fragments
/// when it borders none), or the largest core when it is cut off. Then
/// adjacent cores are merged again when they are coplanar or meet convexly
/// (`convexity`), judged on each core's centroid and PCA normal of `points`
/// (the image's points, sensor frame, NaN where no segment): a crease
/// found between two faces of one object (normal noise) is convex or
/// coplanar, the edge between a box and what stands on it concave. Other geometric
/// segments stay whole. Returns the final segment per pixel (-1 = none;
/// ids are arbitrary but distinct). Allocates.
std::vector<int> SplitSegments(int width, int height, const std::vector<Eigen::Vector3f>& points,
                               const std::vector<int>& geometric, const std::vector<int>& fragments,
                               int min_core, const ConvexityParams& convexity);

}  // namespace iplan::cloud::internal
