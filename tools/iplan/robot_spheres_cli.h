// The logic behind `iplan robot spheres` (tools/iplan/cmd_robot.cc parses
// the arguments): the sphere cover of a robot's collision geometry, per link.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>

namespace iplan::collision {

struct RobotSpheresOptions {
  std::string robot;             ///< a URDF, a URDF overlay or a DH YAML (docs/robots.md)
  bool json = false;             ///< one JSON document instead of the table
  std::string out;               ///< write the cover here (JSON, link frames), empty = do not
  std::optional<double> max_excess;  ///< m; overrides MeshCoverParams::max_excess
  bool no_cache = false;         ///< compute every mesh cover, read and write no cache
};

/// Loads the robot (covering its meshes, with the cover cache unless
/// no_cache) and prints per link: shapes, spheres, uncovered_vertices,
/// max_excess_m (how far its spheres may reach beyond its geometry, m) and
/// sampled_excess_m (how far they are seen to reach: 256 points per sphere;
/// for primitives their bound) and whether the cover came from the cache.
/// With json, exactly one document:
///   {"robot":NAME,"file":PATH,"total_spheres":N,"median_max_excess_m":M,
///    "max_max_excess_m":M,"uncovered_vertices":N,
///    "links":[{"link":..,"shapes":[..],"spheres":N,"uncovered_vertices":N,
///              "max_excess_m":M,"sampled_excess_m":M,"mesh_files":[..],"from_cache":bool},..],
///    "self_collision":{"samples":N,"checked":[[LINK,LINK],..],
///                      "skipped":[{"links":[LINK,LINK],"reason":"adjacent|always|never","min_distance_m":M},..]}}
/// (self_collision.h: the link pairs worth checking, found by sampling).
/// The median is over the links that have collision geometry. `out` gets
/// {"robot":..,"spheres":[{"link":..,"centre":[x,y,z],"radius":r},..]}
/// (centres in the link frame, m), written atomically.
/// @returns 0 when every vertex is covered, 1 when one is not (a bug), 2 on
/// bad input (printed to `err`). Does not throw.
int RunRobotSpheres(const RobotSpheresOptions& options, std::ostream& out, std::ostream& err);

}  // namespace iplan::collision
