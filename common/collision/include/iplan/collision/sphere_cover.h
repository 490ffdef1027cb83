// Covers of primitive shapes by finite sets of spheres that never
// under-cover: every point of the shape lies inside some sphere. Each function
// documents the proof. All lengths in m; shapes are given in some frame F and
// the spheres are returned in the same frame.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace iplan::collision {

/// A sphere: centre (m) in the frame the caller works in, radius (m).
struct Sphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// How fine the covers are.
struct SphereCoverParams {
  /// Cylinders and capsules: the chain is fine enough that each sphere's
  /// radius exceeds the shape's radius by at most this (m), > 0.
  double max_radial_excess = 0.01;
  /// Boxes: cells have half-sizes at most this (m), > 0.
  double max_box_cell_half_size = 0.05;
  /// Returns an empty string when valid, else the reason with the values.
  std::string Validate() const;
};

/// How much a cover over-approximates its shape.
struct CoverReport {
  std::string shape;          ///< "cylinder", "capsule", "box" or "sphere"
  int num_spheres = 0;
  double shape_volume = 0.0;  ///< m^3
  /// Sum of the spheres' volumes over the shape's volume (>= 1; counts
  /// overlaps twice, so it over-states the excess volume).
  double volume_ratio = 1.0;
  /// Upper bound (m) on the distance from any point of the cover to the shape
  /// (the one-sided Hausdorff distance); 0 for a sphere.
  double max_excess = 0.0;
};

/// Cylinder of radius rho and length L, axis = z axis of frame C, centred at
/// C's origin; X_FC is C's pose in F. Returns n spheres with centres on the
/// axis at the midpoints of n equal slabs of half-height w = L / (2n), all of
/// radius r = sqrt(rho^2 + w^2). Proof: a point of the cylinder at height z
/// with distance a <= rho from the axis lies in some slab, |z - z_k| <= w, so
/// its squared distance to z_k's centre is a^2 + (z - z_k)^2 <= rho^2 + w^2.
/// Excess bound: sphere k lies within r - min(rho, w) of the ball of radius
/// min(rho, w) at its centre, which is inside the cylinder.
/// @throws std::invalid_argument if rho or L is not positive and finite.
/// Allocates the result; thread-safe.
std::vector<Sphere> CoverCylinder(double rho, double length, const Eigen::Isometry3d& X_FC,
                                  const SphereCoverParams& params, CoverReport* report);

/// Capsule: points within rho of the segment p1-p2 (frame F). Returns n + 1
/// spheres at n + 1 equally spaced points of the segment including both ends
/// (spacing 2w), radius r = sqrt(rho^2 + w^2). Proof: a point x of the
/// capsule has a nearest segment point s with ||x - s|| <= rho, and x - s is
/// perpendicular to the segment unless s is an end point. Some centre c has
/// ||s - c|| <= w along the segment; in the perpendicular case ||x - c||^2 =
/// ||x - s||^2 + ||s - c||^2 <= r^2; if s is an end point, x is within rho <= r
/// of that end's centre. Excess bound r - rho (each sphere is within r - rho of
/// the ball of radius rho at its centre, which is inside the capsule).
/// @throws std::invalid_argument if rho is not positive or points not finite.
std::vector<Sphere> CoverCapsule(const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                 double rho, const SphereCoverParams& params,
                                 CoverReport* report);

/// Box with half extents h (all > 0) in frame B, X_FB its pose in F. Split
/// into n_x n_y n_z equal cells of half sizes e_i = h_i / n_i; one sphere of
/// radius ||e|| per cell centre. Proof: every point of the box lies in a cell,
/// within ||e|| of the cell centre. Excess bound ||e|| - min_i e_i.
std::vector<Sphere> CoverBox(const Eigen::Vector3d& half_extents, const Eigen::Isometry3d& X_FB,
                             const SphereCoverParams& params, CoverReport* report);

/// Removes spheres that lie entirely inside another sphere of the list
/// (||c_a - c_b|| + r_a <= r_b); the union is unchanged, so covers stay
/// covers. Keeps the first of identical spheres. Returns the kept indices.
std::vector<int> RemoveContainedSpheres(std::vector<Sphere>* spheres);

}  // namespace iplan::collision
