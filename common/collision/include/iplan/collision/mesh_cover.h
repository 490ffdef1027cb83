// Sphere covers of triangle meshes: the collision meshes of vendors' URDFs
// (STL, DAE, OBJ, read by assimp behind this header), turned into the
// spheres every check of the cell works with (robot_model.h).
//
// The cover is conservative: every point of every triangle lies inside some
// sphere (each triangle is split until one sphere holds all three corners of
// each piece; a ball is convex, so it holds the piece). For a point x outside
// the mesh's solid, the distance to the spheres is therefore at most the
// distance to the mesh. It is tight: each sphere is centred at a point c of
// signed depth s(c) (distance to the surface, positive inside the solid,
// negative outside) and has radius r <= s(c) + max_excess, so every point of
// it lies within r - s(c) <= max_excess of the mesh's solid (of the ball of
// radius s(c) about c when c is inside, of c's nearest surface point when it
// is outside): the distance to the spheres is at least the distance to the
// mesh minus max_excess.
//
// Frames: G is the mesh file's frame (the URDF <collision> geometry frame,
// after the URDF's scale); covers are returned in G. Lengths in m.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/sphere_cover.h"

namespace iplan::collision {

/// A triangle mesh in its file's frame G (m).
struct TriangleMesh {
  /// Vertex positions p_GV, 3 x n.
  Eigen::Matrix3Xd vertices;
  /// Vertex indices of each triangle, 3 x m (any winding; the inside test
  /// uses the winding number, whose sign does not matter).
  Eigen::Matrix3Xi triangles;
};

/// Reads the triangles of a mesh file (STL, ASCII or binary; Collada DAE;
/// Wavefront OBJ; anything assimp reads), every mesh of the file's scene
/// with its node transforms applied, identical vertices joined, each axis
/// multiplied by `scale` (the URDF's <mesh scale>). assimp keeps
/// coordinates in single precision: vertices are exact to about 1e-7 relative. Collada files state their
/// unit and are converted to m; STL and OBJ are taken to be in m, as URDF
/// requires.
/// @throws std::runtime_error naming the file: unreadable, no triangles,
///         non-finite coordinates, a scale that is not positive and finite.
TriangleMesh LoadTriangleMesh(const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// How the cover is built.
struct MeshCoverParams {
  /// Each sphere reaches at most this far beyond the mesh (m), > 0.
  double max_excess = 0.025;
  /// Triangles are split until no edge is longer (m), > 0, at most
  /// 1.5 x max_excess (a piece no grid sphere holds gets a sphere of its own
  /// about its centroid, of radius <= 2/3 max_edge).
  double max_edge = 0.01;
  /// Spacing of the grid of candidate centres (m), > 0, at most max_excess.
  double grid_step = 0.01;
  /// Empty when valid, else the reason with the values.
  std::string Validate() const;
};

/// What a mesh cover is.
struct MeshCoverReport {
  CoverReport cover;  ///< shape "mesh"; shape_volume of the closed solid (m^3), 0 if not closed
  int num_vertices = 0;
  int num_triangles = 0;
  /// Vertices of the mesh inside no sphere (checked after the cover is built;
  /// 0 unless the construction is wrong).
  int uncovered_vertices = 0;
  /// The cover's upper bound on how far a sphere reaches beyond the mesh
  /// (m): max over spheres of radius - signed depth of the centre (see the
  /// header comment), <= params.max_excess; equals cover.max_excess.
  double max_excess_m = 0.0;
  /// How far the spheres are seen to reach beyond the mesh (m): the largest
  /// distance to the solid of 256 points on each sphere; <= max_excess_m,
  /// and how loose that bound is.
  double sampled_excess_m = 0.0;
  /// Whether the mesh is a closed solid (winding number 1 inside): only then
  /// are centres placed inside it; an open mesh is covered from its surface.
  bool closed = false;
  /// Hash of the mesh and the parameters (MeshCoverKey), as 16 hex digits.
  std::string key;
  /// Whether the cover came from the cache (MeshCoverCached).
  bool from_cache = false;
};

/// Covers `mesh` (frame G) by spheres in G; see the header comment for what
/// is guaranteed. Greedy set cover over the split triangles with candidate
/// centres on a grid (radius signed depth + max_excess), then each sphere
/// shrunk to the pieces it is the first to hold, then contained spheres
/// removed. Deterministic. Cost: O(grid points x triangles); about a second
/// for a 2000-triangle link.
/// @throws std::invalid_argument for invalid params or an empty mesh.
std::vector<Sphere> CoverMesh(const TriangleMesh& mesh, const MeshCoverParams& params, MeshCoverReport* report);

/// Generalised winding number of `mesh` about the point p_GQ (Jacobson et
/// al. 2013): +-1 inside a closed mesh, 0 outside, in between near holes of
/// an open one. O(triangles); allocates nothing; thread-safe.
double MeshWindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p_GQ);

/// Vertices of `mesh` inside none of `spheres` (same frame), with a
/// tolerance of 1e-9 m. Allocates nothing; O(vertices x spheres).
int CountUncoveredVertices(const TriangleMesh& mesh, const std::vector<Sphere>& spheres);

/// FNV-1a of the mesh's vertices and triangles and of the parameters: the
/// name of its cover in the cache.
std::uint64_t MeshCoverKey(const TriangleMesh& mesh, const MeshCoverParams& params);

/// The folder of the cover cache: $IPLAN_CACHE_DIR/spheres, else
/// $XDG_CACHE_HOME/iplan/spheres, else $HOME/.cache/iplan/spheres; empty when
/// none of them is set (no caching).
std::string DefaultMeshCoverCacheDir();

/// CoverMesh, with the result kept in `cache_dir` (a file per MeshCoverKey,
/// written atomically; a damaged or foreign file is recomputed and
/// replaced). An empty `cache_dir` computes every time; a cache that cannot
/// be written is no error (computed, not kept). Same guarantees as CoverMesh.
std::vector<Sphere> MeshCoverCached(const TriangleMesh& mesh, const MeshCoverParams& params,
                                    const std::string& cache_dir, MeshCoverReport* report);

}  // namespace iplan::collision
