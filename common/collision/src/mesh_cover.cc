// CoverMesh (mesh_cover.h): the split pieces, the candidate centres with
// their signed depth, the greedy set cover.
#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <map>
#include <queue>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "iplan/collision/mesh_cover.h"

namespace iplan::collision {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Piece {
  Eigen::Vector3d a, b, c;
  Eigen::Vector3d Centroid() const { return (a + b + c) / 3.0; }
};

Eigen::Vector3d Corner(const TriangleMesh& m, int t, int k) { return m.vertices.col(m.triangles(k, t)); }

// Longest-edge bisection of every triangle until no edge exceeds max_edge.
std::vector<Piece> SplitTriangles(const TriangleMesh& mesh, double max_edge) {
  std::vector<Piece> out;
  std::vector<Piece> stack;
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    stack.push_back({Corner(mesh, t, 0), Corner(mesh, t, 1), Corner(mesh, t, 2)});
    while (!stack.empty()) {
      Piece p = stack.back();
      stack.pop_back();
      const double ab = (p.b - p.a).squaredNorm(), bc = (p.c - p.b).squaredNorm(), ca = (p.a - p.c).squaredNorm();
      const double longest = std::max({ab, bc, ca});
      if (longest <= max_edge * max_edge) {
        out.push_back(p);
        continue;
      }
      // Rotate so that the longest edge is a-b, then split it at its midpoint.
      if (bc == longest) p = {p.b, p.c, p.a};
      else if (ca == longest) p = {p.c, p.a, p.b};
      const Eigen::Vector3d m = 0.5 * (p.a + p.b);
      stack.push_back({p.a, m, p.c});
      stack.push_back({m, p.b, p.c});
    }
  }
  return out;
}

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection
// 5.1.5: by the Voronoi regions of the corners, edges and face).
Eigen::Vector3d ClosestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Distance from p to the mesh surface (brute force over the triangles).
double SurfaceDistance(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d q = ClosestOnTriangle(p, Corner(mesh, t, 0), Corner(mesh, t, 1), Corner(mesh, t, 2));
    best = std::min(best, (q - p).squaredNorm());
  }
  return std::sqrt(best);
}

// Closed: every undirected edge belongs to exactly two triangles.
bool IsClosed(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> edges;
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.triangles(k, t), v = mesh.triangles((k + 1) % 3, t);
      ++edges[{std::min(u, v), std::max(u, v)}];
    }
  }
  for (const auto& [edge, count] : edges) {
    if (count != 2) return false;
  }
  return !edges.empty();
}

// Volume of a closed mesh (divergence theorem), m^3.
double ClosedVolume(const TriangleMesh& mesh) {
  double v = 0.0;
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    v += Corner(mesh, t, 0).dot(Corner(mesh, t, 1).cross(Corner(mesh, t, 2))) / 6.0;
  }
  return std::abs(v);
}

struct Candidate {
  Eigen::Vector3d centre;
  double depth = 0.0;   // signed: > 0 inside the solid
  double radius = 0.0;  // depth + max_excess
};

// Grid points over the mesh's box grown by max_excess whose sphere of radius
// depth + max_excess is not empty.
std::vector<Candidate> GridCandidates(const TriangleMesh& mesh, bool closed, const MeshCoverParams& params) {
  const Eigen::Vector3d lo = mesh.vertices.rowwise().minCoeff().array() - params.max_excess;
  const Eigen::Vector3d hi = mesh.vertices.rowwise().maxCoeff().array() + params.max_excess;
  const Eigen::Vector3i n = ((hi - lo) / params.grid_step).array().ceil().cast<int>() + 1;
  std::vector<Candidate> out;
  for (int i = 0; i < n.x(); ++i) {
    for (int j = 0; j < n.y(); ++j) {
      for (int k = 0; k < n.z(); ++k) {
        Candidate c;
        c.centre = lo + params.grid_step * Eigen::Vector3d(i, j, k);
        const double d = SurfaceDistance(mesh, c.centre);
        const bool inside = closed && d > 0.0 && std::abs(MeshWindingNumber(mesh, c.centre)) > 0.5;
        c.depth = inside ? d : -d;
        c.radius = c.depth + params.max_excess;
        if (c.radius > 0.0) out.push_back(c);
      }
    }
  }
  return out;
}

bool Holds(const Eigen::Vector3d& centre, double radius, const Piece& p) {
  const double r2 = radius * radius;
  return (p.a - centre).squaredNorm() <= r2 && (p.b - centre).squaredNorm() <= r2 &&
         (p.c - centre).squaredNorm() <= r2;
}

// For every candidate, the pieces it holds whole (a coarse grid of the
// pieces' centroids limits the search).
std::vector<std::vector<int>> HeldPieces(const std::vector<Candidate>& cands, const std::vector<Piece>& pieces,
                                         double cell) {
  std::map<std::array<int, 3>, std::vector<int>> grid;
  auto key = [cell](const Eigen::Vector3d& x) {
    return std::array<int, 3>{static_cast<int>(std::floor(x.x() / cell)), static_cast<int>(std::floor(x.y() / cell)),
                              static_cast<int>(std::floor(x.z() / cell))};
  };
  for (int i = 0; i < static_cast<int>(pieces.size()); ++i) grid[key(pieces[i].Centroid())].push_back(i);
  std::vector<std::vector<int>> held(cands.size());
  for (std::size_t c = 0; c < cands.size(); ++c) {
    const Candidate& cand = cands[c];
    const std::array<int, 3> lo = key(cand.centre.array() - cand.radius);
    const std::array<int, 3> hi = key(cand.centre.array() + cand.radius);
    for (int x = lo[0]; x <= hi[0]; ++x) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int z = lo[2]; z <= hi[2]; ++z) {
          const auto it = grid.find({x, y, z});
          if (it == grid.end()) continue;
          for (int p : it->second) {
            if (Holds(cand.centre, cand.radius, pieces[p])) held[c].push_back(p);
          }
        }
      }
    }
    std::sort(held[c].begin(), held[c].end());
  }
  return held;
}

// Lazy greedy set cover: the candidate holding the most pieces not yet held
// (ties: the lower index), until no candidate adds any. Returns the chosen
// candidates in order.
std::vector<int> GreedyCover(const std::vector<std::vector<int>>& held, std::size_t num_pieces) {
  std::vector<bool> covered(num_pieces, false);
  auto gain = [&](int c) {
    int g = 0;
    for (int p : held[c]) g += covered[p] ? 0 : 1;
    return g;
  };
  // Max-heap on (gain, -index).
  std::priority_queue<std::pair<int, int>> heap;
  for (int c = 0; c < static_cast<int>(held.size()); ++c) {
    if (!held[c].empty()) heap.push({static_cast<int>(held[c].size()), -c});
  }
  std::vector<int> chosen;
  while (!heap.empty()) {
    const auto [stale, neg] = heap.top();
    heap.pop();
    const int c = -neg;
    const int g = gain(c);
    if (g == 0) continue;
    if (g < stale && !heap.empty() && std::make_pair(g, neg) < heap.top()) {
      heap.push({g, neg});
      continue;
    }
    chosen.push_back(c);
    for (int p : held[c]) covered[p] = true;
  }
  // Reverse delete: a chosen sphere all of whose pieces another kept one
  // holds is redundant (greedy's late picks often are).
  std::vector<int> holders(num_pieces, 0);
  for (int c : chosen) {
    for (int p : held[c]) ++holders[p];
  }
  std::vector<int> kept;
  for (auto it = chosen.rbegin(); it != chosen.rend(); ++it) {
    const bool redundant = std::all_of(held[*it].begin(), held[*it].end(), [&](int p) { return holders[p] >= 2; });
    if (!redundant) {
      kept.push_back(*it);
      continue;
    }
    for (int p : held[*it]) --holders[p];
  }
  std::reverse(kept.begin(), kept.end());
  return kept;
}


// The largest distance to the solid of 256 points spread over each sphere
// (a Fibonacci lattice): what the spheres are seen to reach beyond the mesh,
// at most the bound.
double SampledExcess(const TriangleMesh& mesh, bool closed, const std::vector<Sphere>& spheres) {
  constexpr int kPoints = 256;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  double worst = 0.0;
  for (const Sphere& s : spheres) {
    for (int i = 0; i < kPoints; ++i) {
      const double z = 1.0 - 2.0 * (i + 0.5) / kPoints;
      const double rho = std::sqrt(1.0 - z * z);
      const Eigen::Vector3d x = s.centre + s.radius * Eigen::Vector3d(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
      if (closed && std::abs(MeshWindingNumber(mesh, x)) > 0.5) continue;
      worst = std::max(worst, SurfaceDistance(mesh, x));
    }
  }
  return worst;
}

}  // namespace

// The triangles' signed solid angles (Van Oosterom and Strackee's formula)
// over 4 pi.
double MeshWindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double sum = 0.0;
  for (int t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d a = Corner(mesh, t, 0) - p, b = Corner(mesh, t, 1) - p, c = Corner(mesh, t, 2) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * kPi);
}

std::string MeshCoverParams::Validate() const {
  std::ostringstream msg;
  if (!(max_excess > 0.0) || !std::isfinite(max_excess)) {
    msg << "max_excess = " << max_excess << " m must be positive";
  } else if (!(max_edge > 0.0) || !(max_edge <= 1.5 * max_excess)) {
    msg << "max_edge = " << max_edge << " m must be positive and at most 1.5 x max_excess (" << 1.5 * max_excess
        << " m)";
  } else if (!(grid_step > 0.0) || !(grid_step <= max_excess)) {
    msg << "grid_step = " << grid_step << " m must be positive and at most max_excess (" << max_excess << " m)";
  }
  return msg.str();
}

int CountUncoveredVertices(const TriangleMesh& mesh, const std::vector<Sphere>& spheres) {
  int uncovered = 0;
  for (int v = 0; v < mesh.vertices.cols(); ++v) {
    bool in = false;
    for (const Sphere& s : spheres) {
      if ((mesh.vertices.col(v) - s.centre).norm() <= s.radius + 1e-9) {
        in = true;
        break;
      }
    }
    uncovered += in ? 0 : 1;
  }
  return uncovered;
}

std::vector<Sphere> CoverMesh(const TriangleMesh& mesh, const MeshCoverParams& params, MeshCoverReport* report) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (mesh.triangles.cols() == 0 || mesh.vertices.cols() == 0) throw std::invalid_argument("the mesh has no triangles");
  const bool closed = IsClosed(mesh);
  const std::vector<Piece> pieces = SplitTriangles(mesh, params.max_edge);
  const std::vector<Candidate> cands = GridCandidates(mesh, closed, params);
  const std::vector<std::vector<int>> held = HeldPieces(cands, pieces, 2.0 * params.max_excess);
  const std::vector<int> chosen = GreedyCover(held, pieces.size());

  // Each piece to the first chosen sphere holding it; each sphere shrunk to
  // the corners of its own pieces (so radius - depth stays <= max_excess).
  std::vector<int> owner(pieces.size(), -1);
  std::vector<double> r2(chosen.size(), 0.0);
  for (std::size_t s = 0; s < chosen.size(); ++s) {
    const Candidate& c = cands[chosen[s]];
    for (int p : held[chosen[s]]) {
      if (owner[p] >= 0) continue;
      owner[p] = static_cast<int>(s);
      for (const Eigen::Vector3d* x : {&pieces[p].a, &pieces[p].b, &pieces[p].c}) {
        r2[s] = std::max(r2[s], (*x - c.centre).squaredNorm());
      }
    }
  }
  std::vector<Sphere> spheres;
  std::vector<double> depth;
  for (std::size_t s = 0; s < chosen.size(); ++s) {
    if (r2[s] == 0.0) continue;
    spheres.push_back({cands[chosen[s]].centre, std::sqrt(r2[s])});
    depth.push_back(cands[chosen[s]].depth);
  }
  // A piece no candidate holds (possible only on meshes thinner than the
  // grid): a sphere of its own about its centroid (on the surface, depth 0,
  // radius <= 2/3 max_edge <= max_excess).
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    if (owner[p] >= 0) continue;
    const Eigen::Vector3d m = pieces[p].Centroid();
    const double r = std::sqrt(std::max({(pieces[p].a - m).squaredNorm(), (pieces[p].b - m).squaredNorm(),
                                         (pieces[p].c - m).squaredNorm()}));
    spheres.push_back({m, r});
    depth.push_back(0.0);
  }
  const std::vector<int> kept = RemoveContainedSpheres(&spheres);
  double excess = 0.0;
  for (std::size_t i = 0; i < kept.size(); ++i) excess = std::max(excess, spheres[i].radius - depth[kept[i]]);
  if (report != nullptr) {
    report->num_vertices = static_cast<int>(mesh.vertices.cols());
    report->num_triangles = static_cast<int>(mesh.triangles.cols());
    report->closed = closed;
    report->cover.shape = "mesh";
    report->cover.num_spheres = static_cast<int>(spheres.size());
    report->cover.shape_volume = closed ? ClosedVolume(mesh) : 0.0;
    double sum = 0.0;
    for (const Sphere& s : spheres) sum += 4.0 / 3.0 * kPi * s.radius * s.radius * s.radius;
    report->cover.volume_ratio = report->cover.shape_volume > 0.0 ? sum / report->cover.shape_volume : 0.0;
    report->cover.max_excess = excess;
    report->max_excess_m = excess;
    report->uncovered_vertices = CountUncoveredVertices(mesh, spheres);
    report->sampled_excess_m = SampledExcess(mesh, closed, spheres);
  }
  return spheres;
}

}  // namespace iplan::collision
