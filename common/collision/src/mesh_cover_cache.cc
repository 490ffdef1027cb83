// The mesh cover cache (mesh_cover.h): one JSON file per mesh and
// parameters, named by MeshCoverKey, written atomically.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "iplan/collision/mesh_cover.h"
#include "iplan/core/atomic_file.h"
#include "iplan/core/checksum.h"

namespace iplan::collision {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "iplan-mesh-cover";
constexpr int kVersion = 1;

std::string Hex(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

json ToJson(const std::vector<Sphere>& spheres, const MeshCoverReport& r) {
  json s = json::array();
  for (const Sphere& sp : spheres) s.push_back({sp.centre.x(), sp.centre.y(), sp.centre.z(), sp.radius});
  return {{"format", kFormat},
          {"version", kVersion},
          {"key", r.key},
          {"num_vertices", r.num_vertices},
          {"num_triangles", r.num_triangles},
          {"closed", r.closed},
          {"shape_volume_m3", r.cover.shape_volume},
          {"volume_ratio", r.cover.volume_ratio},
          {"max_excess_m", r.max_excess_m},
          {"sampled_excess_m", r.sampled_excess_m},
          {"uncovered_vertices", r.uncovered_vertices},
          {"spheres", s}};
}

// The cached cover when `text` is a cover of this key and mesh; false when
// it is not (damaged, another format or version, another mesh).
bool FromJson(const std::string& text, const TriangleMesh& mesh, const std::string& key, std::vector<Sphere>* spheres,
              MeshCoverReport* r) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || j.value("format", "") != kFormat || j.value("version", 0) != kVersion ||
      j.value("key", "") != key || j.value("num_vertices", -1) != mesh.vertices.cols() ||
      j.value("num_triangles", -1) != mesh.triangles.cols() || !j.contains("spheres") || !j["spheres"].is_array()) {
    return false;
  }
  try {
    spheres->clear();
    for (const json& s : j["spheres"]) {
      const Sphere sp{Eigen::Vector3d(s.at(0).get<double>(), s.at(1).get<double>(), s.at(2).get<double>()),
                      s.at(3).get<double>()};
      if (!sp.centre.allFinite() || !(sp.radius > 0.0) || !std::isfinite(sp.radius)) return false;
      spheres->push_back(sp);
    }
    r->num_vertices = static_cast<int>(mesh.vertices.cols());
    r->num_triangles = static_cast<int>(mesh.triangles.cols());
    r->closed = j.at("closed").get<bool>();
    r->cover.shape = "mesh";
    r->cover.num_spheres = static_cast<int>(spheres->size());
    r->cover.shape_volume = j.at("shape_volume_m3").get<double>();
    r->cover.volume_ratio = j.at("volume_ratio").get<double>();
    r->max_excess_m = j.at("max_excess_m").get<double>();
    r->sampled_excess_m = j.at("sampled_excess_m").get<double>();
    r->cover.max_excess = r->max_excess_m;
  } catch (const json::exception&) {
    return false;
  }
  // Checked again, not taken from the file: a cover that does not hold
  // every vertex is never used.
  r->uncovered_vertices = CountUncoveredVertices(mesh, *spheres);
  return r->uncovered_vertices == 0 && !spheres->empty();
}

}  // namespace

std::uint64_t MeshCoverKey(const TriangleMesh& mesh, const MeshCoverParams& params) {
  std::uint64_t h = core::kStandardFnvSeed;
  const auto add = [&h](const void* p, std::size_t n) { h = core::Fnv1a64(p, n, h); };
  const Eigen::Index nv = mesh.vertices.cols(), nt = mesh.triangles.cols();
  add(&nv, sizeof nv);
  add(mesh.vertices.data(), sizeof(double) * 3 * static_cast<std::size_t>(nv));
  add(&nt, sizeof nt);
  add(mesh.triangles.data(), sizeof(int) * 3 * static_cast<std::size_t>(nt));
  for (double v : {params.max_excess, params.max_edge, params.grid_step}) add(&v, sizeof v);
  add(&kVersion, sizeof kVersion);
  return h;
}

std::string DefaultMeshCoverCacheDir() {
  if (const char* d = std::getenv("IPLAN_CACHE_DIR"); d != nullptr && *d != '\0') return std::string(d) + "/spheres";
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d != nullptr && *d != '\0') {
    return std::string(d) + "/iplan/spheres";
  }
  if (const char* d = std::getenv("HOME"); d != nullptr && *d != '\0') return std::string(d) + "/.cache/iplan/spheres";
  return "";
}

std::vector<Sphere> MeshCoverCached(const TriangleMesh& mesh, const MeshCoverParams& params,
                                    const std::string& cache_dir, MeshCoverReport* report) {
  MeshCoverReport local;
  MeshCoverReport* r = report != nullptr ? report : &local;
  const std::string key = Hex(MeshCoverKey(mesh, params));
  const std::string file = cache_dir.empty() ? "" : cache_dir + "/" + key + ".json";
  std::vector<Sphere> spheres;
  if (!file.empty()) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    if (in && FromJson(text.str(), mesh, key, &spheres, r)) {
      r->key = key;
      r->from_cache = true;
      return spheres;
    }
  }
  spheres = CoverMesh(mesh, params, r);
  r->key = key;
  r->from_cache = false;
  if (!file.empty() && r->uncovered_vertices == 0) {
    std::error_code ec;
    std::filesystem::create_directories(cache_dir, ec);
    try {
      core::WriteFileAtomically(file, ToJson(spheres, *r).dump() + "\n");
    } catch (const std::runtime_error&) {
      // A cache that cannot be written costs time, never correctness.
    }
  }
  return spheres;
}

}  // namespace iplan::collision
