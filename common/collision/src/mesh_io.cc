// LoadTriangleMesh (mesh_cover.h): assimp reads the file; nothing of
// assimp leaves this file.
#include <array>
#include <cmath>
#include <map>
#include <functional>
#include <stdexcept>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "iplan/collision/mesh_cover.h"

namespace iplan::collision {
namespace {

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

}  // namespace

TriangleMesh LoadTriangleMesh(const std::string& path, const Eigen::Vector3d& scale) {
  if (!scale.allFinite() || !(scale.minCoeff() > 0.0)) {
    Fail(path, "mesh scale (" + std::to_string(scale.x()) + ", " + std::to_string(scale.y()) + ", " +
                   std::to_string(scale.z()) + ") must be positive and finite");
  }
  Assimp::Importer importer;
  // Points and lines are dropped; polygons become triangles.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    Fail(path, std::string("cannot read the mesh (") + importer.GetErrorString() + ")");
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
  std::map<std::array<double, 3>, int> welded;
  // Every mesh of every node, with the node's transform to the file's root.
  std::function<void(const aiNode*, const aiMatrix4x4&)> visit = [&](const aiNode* node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 X = parent * node->mTransformation;
    for (unsigned m = 0; m < node->mNumMeshes; ++m) {
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[m]];
      // Corners at the same position are one vertex, whatever their
      // normals (assimp keeps an STL's corners apart by their face normal),
      // so that shared edges are shared and a closed mesh is seen closed.
      std::vector<int> index(mesh->mNumVertices);
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D p = X * mesh->mVertices[v];
        const Eigen::Vector3d x(scale.x() * p.x, scale.y() * p.y, scale.z() * p.z);
        const auto [it, added] = welded.try_emplace({x.x(), x.y(), x.z()}, static_cast<int>(vertices.size()));
        if (added) vertices.push_back(x);
        index[v] = it->second;
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) continue;
        const Eigen::Vector3i t(index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]);
        // A triangle that welding made degenerate adds nothing to cover.
        if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) triangles.push_back(t);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], X);
  };
  visit(scene->mRootNode, aiMatrix4x4());
  if (triangles.empty()) Fail(path, "the mesh has no triangles");
  TriangleMesh out;
  out.vertices.resize(3, static_cast<int>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (!vertices[i].allFinite()) Fail(path, "vertex " + std::to_string(i) + " is not finite");
    out.vertices.col(static_cast<int>(i)) = vertices[i];
  }
  out.triangles.resize(3, static_cast<int>(triangles.size()));
  for (std::size_t i = 0; i < triangles.size(); ++i) out.triangles.col(static_cast<int>(i)) = triangles[i];
  return out;
}

}  // namespace iplan::collision
