// URDF mesh collision shapes (robot_model_mesh.h).
#include "robot_model_mesh.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace iplan::collision {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& urdf, const std::string& link, const std::string& what) {
  throw std::runtime_error(urdf + ": link '" + link + "': " + what);
}

bool StartsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::string ResolveMeshFile(const std::string& urdf_path, const std::string& link, const std::string& filename) {
  const fs::path urdf_dir = fs::absolute(fs::path(urdf_path)).parent_path();
  if (StartsWith(filename, "file://")) return filename.substr(7);
  if (!StartsWith(filename, "package://")) {
    const fs::path p(filename);
    return (p.is_absolute() ? p : urdf_dir / p).lexically_normal().string();
  }
  const std::string rest = filename.substr(10);
  const std::size_t slash = rest.find('/');
  if (slash == std::string::npos || slash == 0) Fail(urdf_path, link, "mesh '" + filename + "' names no package");
  const std::string package = rest.substr(0, slash);
  const std::string inside = rest.substr(slash + 1);
  std::vector<fs::path> tried;
  if (const char* env = std::getenv("ROS_PACKAGE_PATH"); env != nullptr) {
    std::stringstream paths(env);
    std::string dir;
    while (std::getline(paths, dir, ':')) {
      if (!dir.empty()) tried.push_back(fs::path(dir) / package / inside);
    }
  }
  for (fs::path d = urdf_dir; !d.empty(); d = d.parent_path()) {
    if (d.filename() == package) tried.push_back(d / inside);
    if (d == d.root_path()) break;
  }
  for (const fs::path& p : tried) {
    if (fs::exists(p)) return p.lexically_normal().string();
  }
  Fail(urdf_path, link,
       "mesh '" + filename + "': package '" + package + "' is neither on $ROS_PACKAGE_PATH nor a folder above the URDF");
}

std::vector<Sphere> CoverUrdfMesh(const std::string& urdf_path, const std::string& link, const std::string& filename,
                                  const Eigen::Vector3d& scale, const Eigen::Isometry3d& X_LG,
                                  const RobotModelOptions& options, ShapeCoverEntry* entry) {
  const std::string file = ResolveMeshFile(urdf_path, link, filename);
  TriangleMesh mesh;
  try {
    mesh = LoadTriangleMesh(file, scale);
  } catch (const std::runtime_error& e) {
    Fail(urdf_path, link, e.what());
  }
  MeshCoverReport report;
  const std::string cache = options.mesh_cache_dir.value_or(DefaultMeshCoverCacheDir());
  std::vector<Sphere> spheres;
  try {
    spheres = MeshCoverCached(mesh, options.mesh_cover, cache, &report);
  } catch (const std::invalid_argument& e) {
    Fail(urdf_path, link, std::string("mesh cover of ") + file + ": " + e.what());
  }
  if (report.uncovered_vertices != 0) {
    Fail(urdf_path, link, "the cover of " + file + " leaves " + std::to_string(report.uncovered_vertices) +
                              " vertices outside every sphere (a bug)");
  }
  for (Sphere& s : spheres) s.centre = X_LG * s.centre;
  entry->link = link;
  entry->cover = report.cover;
  entry->mesh_file = file;
  entry->mesh = report;
  return spheres;
}

}  // namespace iplan::collision
