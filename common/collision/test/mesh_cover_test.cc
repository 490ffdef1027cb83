// Mesh covers (mesh_cover.h) checked against what they promise: every point
// of the surface inside a sphere, no sphere reaching more than the stated
// excess beyond the mesh, and distances that agree with FCL's distance to the
// mesh itself; on a cube with a closed form and on the UR5e's real meshes.
#include "iplan/collision/mesh_cover.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>

#include <fcl/fcl.h>
#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include "iplan/collision/robot_model.h"

namespace iplan::collision {
namespace {

namespace fs = std::filesystem;

const std::string kUr5e = std::string(IPLAN_SHARED_DIR) + "/robots/ur5e";

fs::path TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("iplan_mesh_cover_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A cube of edge 0.2 m centred at the origin, as a Wavefront OBJ file.
std::string WriteCubeObj(const fs::path& dir) {
  const std::string path = (dir / "cube.obj").string();
  std::ofstream f(path);
  for (int i = 0; i < 8; ++i) {
    f << "v " << ((i & 1) ? 0.1 : -0.1) << ' ' << ((i & 2) ? 0.1 : -0.1) << ' ' << ((i & 4) ? 0.1 : -0.1) << '\n';
  }
  // Faces as quads (assimp triangulates), corner indices 1-based.
  f << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return path;
}

double DistanceToSpheres(const std::vector<Sphere>& spheres, const Eigen::Vector3d& x) {
  double d = std::numeric_limits<double>::infinity();
  for (const Sphere& s : spheres) d = std::min(d, (x - s.centre).norm() - s.radius);
  return std::max(d, 0.0);
}

// Uniform points on the mesh's triangles (by area), seeded.
std::vector<Eigen::Vector3d> SurfaceSamples(const TriangleMesh& m, int n, std::uint64_t seed) {
  std::vector<double> area(m.triangles.cols());
  for (int t = 0; t < m.triangles.cols(); ++t) {
    const Eigen::Vector3d a = m.vertices.col(m.triangles(0, t)), b = m.vertices.col(m.triangles(1, t)),
                          c = m.vertices.col(m.triangles(2, t));
    area[t] = 0.5 * (b - a).cross(c - a).norm();
  }
  std::mt19937_64 rng(seed);
  std::discrete_distribution<int> pick(area.begin(), area.end());
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    const int t = pick(rng);
    double u = u01(rng), v = u01(rng);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Eigen::Vector3d a = m.vertices.col(m.triangles(0, t)), b = m.vertices.col(m.triangles(1, t)),
                          c = m.vertices.col(m.triangles(2, t));
    out.push_back(a + u * (b - a) + v * (c - a));
  }
  return out;
}

// Distance from x to the cube's solid (closed form).
double CubeDistance(const Eigen::Vector3d& x) { return (x.cwiseAbs().array() - 0.1).cwiseMax(0.0).matrix().norm(); }

TEST(MeshCoverTest, CubeFromObjIsCoveredWithinTheStatedExcess) {
  const fs::path dir = TempDir("cube");
  const TriangleMesh cube = LoadTriangleMesh(WriteCubeObj(dir));
  EXPECT_EQ(cube.vertices.cols(), 8);
  EXPECT_EQ(cube.triangles.cols(), 12);
  MeshCoverParams params;
  MeshCoverReport report;
  const std::vector<Sphere> spheres = CoverMesh(cube, params, &report);
  EXPECT_TRUE(report.closed);
  EXPECT_NEAR(report.cover.shape_volume, 0.008, 1e-8);
  EXPECT_EQ(report.uncovered_vertices, 0);
  EXPECT_LE(report.max_excess_m, params.max_excess + 1e-12);
  EXPECT_GT(report.max_excess_m, 0.0);
  EXPECT_EQ(report.cover.num_spheres, static_cast<int>(spheres.size()));
  // Every surface point is inside a sphere.
  for (const Eigen::Vector3d& x : SurfaceSamples(cube, 5000, 3)) ASSERT_EQ(DistanceToSpheres(spheres, x), 0.0) << x.transpose();
  // No point of any sphere is farther than the stated excess from the cube.
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n01;
  double worst = 0.0;
  for (const Sphere& s : spheres) {
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d dir3(n01(rng), n01(rng), n01(rng));
      worst = std::max(worst, CubeDistance(s.centre + s.radius * dir3.normalized()));
    }
  }
  EXPECT_LE(worst, report.max_excess_m + 1e-12);
  EXPECT_GT(worst, 0.5 * report.max_excess_m) << "the bound should not be far above what the spheres reach";
  // The scale of a URDF <mesh> multiplies each axis.
  const TriangleMesh scaled = LoadTriangleMesh((dir / "cube.obj").string(), {2.0, 1.0, 0.5});
  EXPECT_NEAR(scaled.vertices.row(0).maxCoeff(), 0.2, 1e-6);  // assimp reads single precision
  EXPECT_NEAR(scaled.vertices.row(2).maxCoeff(), 0.05, 1e-6);
  fs::remove_all(dir);
}

TEST(MeshCoverTest, BadMeshesAndParamsAreRefusedByName) {
  const fs::path dir = TempDir("bad");
  const std::string missing = (dir / "nothing.stl").string();
  try {
    LoadTriangleMesh(missing);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string cube = WriteCubeObj(dir);
  EXPECT_THROW(LoadTriangleMesh(cube, {1.0, 0.0, 1.0}), std::runtime_error);
  EXPECT_THROW(LoadTriangleMesh(cube, {1.0, std::nan(""), 1.0}), std::runtime_error);
  MeshCoverParams p;
  p.max_edge = 0.05;  // more than 1.5 x max_excess
  EXPECT_NE(p.Validate().find("max_edge"), std::string::npos);
  EXPECT_THROW(CoverMesh(LoadTriangleMesh(cube), p, nullptr), std::invalid_argument);
  fs::remove_all(dir);
}

TEST(MeshCoverTest, CacheReturnsTheSameCoverAndReplacesADamagedFile) {
  const fs::path dir = TempDir("cache");
  const TriangleMesh cube = LoadTriangleMesh(WriteCubeObj(dir));
  const std::string cache = (dir / "cache").string();
  MeshCoverReport first, second, third;
  const std::vector<Sphere> a = MeshCoverCached(cube, {}, cache, &first);
  const std::vector<Sphere> b = MeshCoverCached(cube, {}, cache, &second);
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(first.key, second.key);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].centre, b[i].centre);
    EXPECT_EQ(a[i].radius, b[i].radius);
  }
  EXPECT_EQ(second.max_excess_m, first.max_excess_m);
  const std::string file = cache + "/" + first.key + ".json";
  ASSERT_TRUE(fs::exists(file));
  std::ofstream(file) << "{\"format\": \"iplan-mesh-cover\", \"spheres\": [[0,0";
  const std::vector<Sphere> c = MeshCoverCached(cube, {}, cache, &third);
  EXPECT_FALSE(third.from_cache);
  EXPECT_EQ(c.size(), a.size());
  MeshCoverReport again;
  MeshCoverCached(cube, {}, cache, &again);
  EXPECT_TRUE(again.from_cache) << "the damaged file was not replaced";
  // Other parameters are another cover.
  MeshCoverParams finer;
  finer.max_excess = 0.01;
  finer.max_edge = 0.01;
  MeshCoverReport other;
  MeshCoverCached(cube, finer, cache, &other);
  EXPECT_NE(other.key, first.key);
  EXPECT_FALSE(other.from_cache);
  fs::remove_all(dir);
}

std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> FclMesh(const TriangleMesh& m) {
  auto bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Vector3d> v;
  std::vector<fcl::Triangle> t;
  for (int i = 0; i < m.vertices.cols(); ++i) v.push_back(m.vertices.col(i));
  for (int i = 0; i < m.triangles.cols(); ++i) t.emplace_back(m.triangles(0, i), m.triangles(1, i), m.triangles(2, i));
  bvh->beginModel();
  bvh->addSubModel(v, t);
  bvh->endModel();
  return bvh;
}

// FCL's distance from the point x (a sphere of radius 0) to the mesh at X_WG.
double FclPointDistance(const std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>>& bvh, const Eigen::Isometry3d& X_WG,
                        const Eigen::Vector3d& x) {
  fcl::CollisionObjectd mesh(bvh, fcl::Transform3d(X_WG.matrix()));
  fcl::Transform3d X_WP = fcl::Transform3d::Identity();
  X_WP.translation() = x;
  fcl::CollisionObjectd point(std::make_shared<fcl::Sphered>(0.0), X_WP);
  fcl::DistanceRequestd request;
  fcl::DistanceResultd result;
  fcl::distance(&mesh, &point, request, result);
  return result.min_distance;
}

TEST(MeshCoverTest, Ur5eMeshesAgreeWithFclWithinTheExcess) {
  const fs::path dir = TempDir("ur5e");
  std::vector<double> excess;
  for (const char* name : {"base", "shoulder", "upperarm", "forearm", "wrist1", "wrist2", "wrist3"}) {
    SCOPED_TRACE(name);
    const TriangleMesh mesh = LoadTriangleMesh(kUr5e + "/meshes/collision/" + name + ".stl");
    MeshCoverReport report;
    const std::vector<Sphere> spheres = MeshCoverCached(mesh, {}, (dir / "cache").string(), &report);
    EXPECT_EQ(report.uncovered_vertices, 0);
    EXPECT_LE(report.max_excess_m, MeshCoverParams{}.max_excess + 1e-12);
    excess.push_back(report.max_excess_m);
    for (const Eigen::Vector3d& x : SurfaceSamples(mesh, 3000, 5)) {
      ASSERT_LE(DistanceToSpheres(spheres, x), 1e-12) << x.transpose();
    }
    // Points around the link, outside its solid: the spheres are never
    // farther than the mesh, and nearer by at most the excess.
    const auto bvh = FclMesh(mesh);
    const Eigen::Vector3d lo = mesh.vertices.rowwise().minCoeff().array() - 0.1;
    const Eigen::Vector3d hi = mesh.vertices.rowwise().maxCoeff().array() + 0.1;
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    int checked = 0;
    for (int k = 0; k < 400; ++k) {
      const Eigen::Vector3d x = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u01(rng), u01(rng), u01(rng)));
      if (std::abs(MeshWindingNumber(mesh, x)) > 0.5) continue;
      const double d_mesh = FclPointDistance(bvh, Eigen::Isometry3d::Identity(), x);
      const double d_spheres = DistanceToSpheres(spheres, x);
      ASSERT_LE(d_spheres, d_mesh + 1e-9) << x.transpose();
      ASSERT_GE(d_spheres, d_mesh - report.max_excess_m - 1e-9) << x.transpose();
      ++checked;
    }
    EXPECT_GT(checked, 200);
  }
  std::sort(excess.begin(), excess.end());
  EXPECT_LE(excess[excess.size() / 2], 0.025) << "median max_excess_m over the links";
  fs::remove_all(dir);
}


Eigen::Isometry3d ToIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  X.linear() = Eigen::Quaterniond(w, x, y, z).toRotationMatrix();
  return X;
}

TEST(MeshCoverTest, Ur5eRobotSpheresAgreeWithFclOverSampledConfigurations) {
  const fs::path dir = TempDir("ur5e_robot");
  RobotModelOptions options;
  options.mesh_cache_dir = (dir / "cache").string();
  const std::string urdf_path = kUr5e + "/ur5e.urdf";
  const RobotModel robot = LoadRobotModel(urdf_path, options);
  EXPECT_EQ(robot.nq, 6);
  ASSERT_EQ(robot.cover_report.size(), 7u);
  double worst_excess = 0.0;
  for (const ShapeCoverEntry& e : robot.cover_report) {
    ASSERT_TRUE(e.mesh.has_value()) << e.link;
    EXPECT_EQ(e.mesh->uncovered_vertices, 0) << e.link;
    worst_excess = std::max(worst_excess, e.mesh->max_excess_m);
  }
  // The meshes where the URDF puts them, for FCL.
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDFFile(urdf_path);
  ASSERT_TRUE(urdf);
  struct Placed {
    int link;
    Eigen::Isometry3d X_LG;
    std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> bvh;
    TriangleMesh mesh;
  };
  std::vector<Placed> meshes;
  for (const ShapeCoverEntry& e : robot.cover_report) {
    const urdf::LinkConstSharedPtr link = urdf->getLink(e.link);
    ASSERT_TRUE(link && link->collision);
    const TriangleMesh mesh = LoadTriangleMesh(e.mesh_file);
    meshes.push_back({robot.FindLink(e.link), ToIsometry(link->collision->origin), FclMesh(mesh), mesh});
  }
  RobotData data(robot);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int checked = 0;
  for (int c = 0; c < 20; ++c) {
    Eigen::VectorXd q(robot.nq);
    for (int i = 0; i < robot.nq; ++i) q[i] = -3.0 + 6.0 * u01(rng);
    CalcForwardKinematics(robot, q, &data);
    std::vector<Sphere> world;
    for (int s = 0; s < static_cast<int>(robot.spheres.size()); ++s) {
      world.push_back({data.p_WS.col(s), robot.spheres[s].radius});
    }
    for (int k = 0; k < 100; ++k) {
      // Points in the arm's reach, 0.05 to 0.3 m from it.
      const Eigen::Vector3d x(-1.0 + 2.0 * u01(rng), -1.0 + 2.0 * u01(rng), -0.2 + 1.4 * u01(rng));
      double d_mesh = std::numeric_limits<double>::infinity();
      bool inside = false;
      for (const Placed& m : meshes) {
        const Eigen::Isometry3d X_WG = data.X_WL[m.link] * m.X_LG;
        d_mesh = std::min(d_mesh, FclPointDistance(m.bvh, X_WG, x));
        inside = inside || std::abs(MeshWindingNumber(m.mesh, X_WG.inverse() * x)) > 0.5;
      }
      if (inside || d_mesh < 0.05 || d_mesh > 0.3) continue;
      const double d_spheres = DistanceToSpheres(world, x);
      ASSERT_LE(d_spheres, d_mesh + 1e-9) << "q " << q.transpose() << " x " << x.transpose();
      ASSERT_GE(d_spheres, d_mesh - worst_excess - 1e-9) << "q " << q.transpose() << " x " << x.transpose();
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace iplan::collision
