#include "iplan/collision/robot_model.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>


#include "alloc_counter.h"

#include "iplan/collision/sphere_cover.h"

namespace iplan::collision {
namespace {

const std::string kUrdf = std::string(IPLAN_SHARED_DIR) + "/robots/panda/panda_collision.urdf";
const std::string kYaml = std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml";
constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d RandomUnit(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  return Eigen::Vector3d(n01(*rng), n01(*rng), n01(*rng)).normalized();
}

// Random points of a cylinder (radius rho, length L, axis z, centred): half
// in the volume, half on the surface, including the rims (worst case for a
// sphere chain).
std::vector<Eigen::Vector3d> SampleCylinder(double rho, double L, int n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) {
    const double th = 2 * kPi * u01(*rng);
    double a = rho * std::sqrt(u01(*rng));
    double z = L * (u01(*rng) - 0.5);
    switch (i % 4) {
      case 1: a = rho; break;                                   // side
      case 2: z = u01(*rng) < 0.5 ? -0.5 * L : 0.5 * L; break;  // caps
      case 3: a = rho; z = u01(*rng) < 0.5 ? -0.5 * L : 0.5 * L; break;  // rims
      default: break;
    }
    pts.emplace_back(a * std::cos(th), a * std::sin(th), z);
  }
  return pts;
}

std::vector<Eigen::Vector3d> SampleBall(double r, int n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) {
    const double rr = i % 2 == 0 ? r : r * std::cbrt(u01(*rng));
    pts.push_back(rr * RandomUnit(rng));
  }
  return pts;
}

std::vector<Eigen::Vector3d> SampleBox(const Eigen::Vector3d& h, int n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u11(-1.0, 1.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d p(u11(*rng), u11(*rng), u11(*rng));
    if (i % 2 == 1) p[i % 3] = p[i % 3] < 0 ? -1.0 : 1.0;          // faces
    if (i % 8 == 7) p = p.cwiseSign();                             // corners
    pts.push_back(p.cwiseProduct(h));
  }
  return pts;
}

bool Covered(const std::vector<Sphere>& spheres, const Eigen::Vector3d& p, double tol = 1e-12) {
  for (const Sphere& s : spheres) {
    if ((p - s.centre).norm() <= s.radius + tol) return true;
  }
  return false;
}

Eigen::Isometry3d RandomPose(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  Eigen::Quaterniond q(n01(*rng), n01(*rng), n01(*rng), n01(*rng));
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(n01(*rng), n01(*rng), n01(*rng));
  return X;
}

TEST(SphereCoverTest, CoversNeverUnderCoverAndExcessBoundHolds) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    SphereCoverParams params;
    params.max_radial_excess = 0.002 + 0.03 * u01(rng);
    params.max_box_cell_half_size = 0.01 + 0.1 * u01(rng);
    const Eigen::Isometry3d X = RandomPose(&rng);
    const double rho = 0.01 + 0.1 * u01(rng);
    const double L = 0.001 + 0.5 * u01(rng);
    CoverReport rep;
    // Cylinder.
    const auto cyl = CoverCylinder(rho, L, X, params, &rep);
    for (const auto& p : SampleCylinder(rho, L, 400, &rng)) {
      ASSERT_TRUE(Covered(cyl, X * p)) << trial;
    }
    EXPECT_EQ(rep.num_spheres, static_cast<int>(cyl.size()));
    EXPECT_LE(cyl[0].radius - rho, params.max_radial_excess * (1 + 1e-12));
    EXPECT_GE(rep.volume_ratio, 1.0);
    // Excess bound: points on the spheres are within max_excess of the shape.
    for (const Sphere& s : cyl) {
      for (int i = 0; i < 50; ++i) {
        const Eigen::Vector3d p_C = X.inverse() * (s.centre + s.radius * RandomUnit(&rng));
        const double radial = std::max(0.0, p_C.head<2>().norm() - rho);
        const double axial = std::max(0.0, std::abs(p_C.z()) - 0.5 * L);
        ASSERT_LE(std::hypot(radial, axial), rep.max_excess + 1e-12);
      }
    }
    // Capsule.
    const Eigen::Vector3d p1 = X.translation();
    const Eigen::Vector3d p2 = p1 + L * RandomUnit(&rng);
    const auto cap = CoverCapsule(p1, p2, rho, params, &rep);
    for (int i = 0; i < 400; ++i) {
      const double t = i % 3 == 0 ? (i % 2) : u01(rng);
      const Eigen::Vector3d s = (1 - t) * p1 + t * p2;
      Eigen::Vector3d dir = RandomUnit(&rng);
      if (i % 3 != 0) dir = (dir - dir.dot((p2 - p1).normalized()) * (p2 - p1).normalized()).normalized();
      ASSERT_TRUE(Covered(cap, s + rho * (i % 5 == 0 ? std::cbrt(u01(rng)) : 1.0) * dir)) << trial;
    }
    EXPECT_LE(rep.max_excess, params.max_radial_excess * (1 + 1e-12));
    // Box.
    const Eigen::Vector3d h(0.01 + 0.2 * u01(rng), 0.01 + 0.2 * u01(rng), 0.01 + 0.2 * u01(rng));
    const auto box = CoverBox(h, X, params, &rep);
    for (const auto& p : SampleBox(h, 400, &rng)) ASSERT_TRUE(Covered(box, X * p)) << trial;
  }
  EXPECT_THROW(CoverCylinder(-1.0, 1.0, Eigen::Isometry3d::Identity(), {}, nullptr),
               std::invalid_argument);
}

TEST(SphereCoverTest, RemoveContainedKeepsUnion) {
  std::vector<Sphere> s = {{Eigen::Vector3d::Zero(), 1.0},
                           {Eigen::Vector3d(0.2, 0, 0), 0.5},
                           {Eigen::Vector3d(0.9, 0, 0), 0.5},
                           {Eigen::Vector3d::Zero(), 1.0}};
  const std::vector<int> kept = RemoveContainedSpheres(&s);
  EXPECT_EQ(kept, (std::vector<int>{0, 2}));
}

// Configuration of the URDF model (7 arm joints + the finger) from the arm
// configuration and the finger opening.
Eigen::VectorXd UrdfQ(const RobotModel& urdf, const Eigen::VectorXd& q_arm, double finger) {
  Eigen::VectorXd q(urdf.nq);
  q.head(7) = q_arm;
  q[7] = finger;
  return q;
}

TEST(RobotModelTest, PandaYamlForwardKinematicsMatchesUrdf) {
  const RobotModel urdf = LoadRobotModelFromUrdf(kUrdf);
  const RobotModel yaml = LoadRobotModelFromYaml(kYaml);
  ASSERT_EQ(urdf.nq, 8);  // 7 arm joints + finger 1 (finger 2 mimics it)
  ASSERT_EQ(yaml.nq, 7);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(urdf.joints[urdf.q_joints[i]].name, yaml.joints[yaml.q_joints[i]].name);
  }
  RobotData du(urdf), dy(yaml);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Eigen::VectorXd lo = yaml.LowerLimits(), hi = yaml.UpperLimits();
  RecordProperty("yaml_spheres", static_cast<int>(yaml.spheres.size()));
  RecordProperty("urdf_spheres", static_cast<int>(urdf.spheres.size()));
  const std::vector<std::string> frames = {"panda_link0", "panda_link1", "panda_link2",
                                           "panda_link3", "panda_link4", "panda_link5",
                                           "panda_link6", "panda_link7", "panda_link8",
                                           "panda_hand"};
  for (int trial = 0; trial < 1000; ++trial) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i) {
      // Beyond the limits too: the kinematics must agree everywhere.
      q[i] = lo[i] - 0.5 + (hi[i] - lo[i] + 1.0) * u01(rng);
    }
    CalcForwardKinematics(urdf, UrdfQ(urdf, q, 0.04 * u01(rng)), &du);
    CalcForwardKinematics(yaml, q, &dy);
    for (const std::string& f : frames) {
      const Eigen::Isometry3d& A = du.X_WL[urdf.FindLink(f)];
      const Eigen::Isometry3d& B = dy.X_WL[yaml.FindLink(f)];
      ASSERT_LE((A.translation() - B.translation()).norm(), 1e-9) << f << " trial " << trial;
      ASSERT_LE((A.linear() - B.linear()).norm(), 1e-9) << f << " trial " << trial;
    }
  }
}

TEST(RobotModelTest, PandaYamlLimitsMatchUrdf) {
  const RobotModel urdf = LoadRobotModelFromUrdf(kUrdf);
  const RobotModel yaml = LoadRobotModelFromYaml(kYaml);
  for (int i = 0; i < 7; ++i) {
    const JointLimits& a = urdf.joints[urdf.q_joints[i]].limits;
    const JointLimits& b = yaml.joints[yaml.q_joints[i]].limits;
    EXPECT_DOUBLE_EQ(a.lower, b.lower) << i;
    EXPECT_DOUBLE_EQ(a.upper, b.upper) << i;
    EXPECT_DOUBLE_EQ(a.velocity, b.velocity) << i;
    EXPECT_GE(b.acceleration, 7.5);
    EXPECT_GE(b.jerk, 3750.0);
  }
  // URDF has no acceleration limits: the documented default is used.
  EXPECT_EQ(urdf.joints[urdf.q_joints[0]].limits.acceleration, RobotModelOptions{}.default_acceleration);
}

// Every point of every collision shape of the URDF (at random configurations
// and finger openings) lies inside some sphere of the URDF-derived model and
// of the YAML model.
TEST(RobotModelTest, SpheresCoverEveryUrdfCollisionShape) {
  const RobotModel urdf = LoadRobotModelFromUrdf(kUrdf);
  const RobotModel yaml = LoadRobotModelFromYaml(kYaml);
  // Independent read of the shapes.
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(kUrdf);
  ASSERT_TRUE(model);
  RobotData du(urdf), dy(yaml);
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Eigen::VectorXd lo = yaml.LowerLimits(), hi = yaml.UpperLimits();
  int shapes_checked = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i) q[i] = lo[i] + (hi[i] - lo[i]) * u01(rng);
    const double finger = trial == 0 ? 0.0 : trial == 1 ? 0.04 : 0.04 * u01(rng);
    CalcForwardKinematics(urdf, UrdfQ(urdf, q, finger), &du);
    CalcForwardKinematics(yaml, q, &dy);
    auto to_spheres = [](const RobotData& d, const RobotModel& m) {
      std::vector<Sphere> s;
      for (size_t i = 0; i < m.spheres.size(); ++i) {
        s.push_back({d.p_WS.col(static_cast<Eigen::Index>(i)), m.spheres[i].radius});
      }
      return s;
    };
    const std::vector<Sphere> su = to_spheres(du, urdf), sy = to_spheres(dy, yaml);
    for (const auto& [name, link] : model->links_) {
      const Eigen::Isometry3d& X_WL = du.X_WL[urdf.FindLink(name)];
      for (const urdf::CollisionSharedPtr& col : link->collision_array) {
        const urdf::Pose& o = col->origin;
        Eigen::Isometry3d X_LG = Eigen::Isometry3d::Identity();
        X_LG.translation() = Eigen::Vector3d(o.position.x, o.position.y, o.position.z);
        X_LG.linear() = Eigen::Quaterniond(o.rotation.w, o.rotation.x, o.rotation.y,
                                           o.rotation.z).toRotationMatrix();
        std::vector<Eigen::Vector3d> pts;
        if (col->geometry->type == urdf::Geometry::SPHERE) {
          pts = SampleBall(static_cast<const urdf::Sphere&>(*col->geometry).radius, 300, &rng);
        } else if (col->geometry->type == urdf::Geometry::CYLINDER) {
          const auto& c = static_cast<const urdf::Cylinder&>(*col->geometry);
          pts = SampleCylinder(c.radius, c.length, 300, &rng);
        } else {
          FAIL() << "unexpected shape in " << name;
        }
        ++shapes_checked;
        for (const Eigen::Vector3d& p_G : pts) {
          const Eigen::Vector3d p_W = X_WL * X_LG * p_G;
          ASSERT_TRUE(Covered(su, p_W, 1e-9)) << name << " (URDF model) trial " << trial;
          ASSERT_TRUE(Covered(sy, p_W, 1e-9)) << name << " (YAML model) trial " << trial;
        }
      }
    }
  }
  // Over-approximation is reported per shape, and every shape was checked.
  EXPECT_EQ(shapes_checked, 20 * static_cast<int>(urdf.cover_report.size()));
  EXPECT_GT(shapes_checked, 20 * 30);
  for (const ShapeCoverEntry& e : yaml.cover_report) {
    EXPECT_GE(e.cover.volume_ratio, 1.0) << e.link;
    if (e.cover.shape == "capsule") {
      EXPECT_LE(e.cover.max_excess, RobotModelOptions{}.cover.max_radial_excess + 1e-12) << e.link;
    }
    EXPECT_GT(e.cover.max_excess, 0.0) << e.link << " " << e.cover.shape;
  }
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

void ExpectThrowsWith(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no exception, expected one containing '" << needle << "'";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(RobotModelTest, LoadErrorsNameTheProblem) {
  ExpectThrowsWith([] { LoadRobotModelFromUrdf("/nonexistent.urdf"); }, "/nonexistent.urdf");
  ExpectThrowsWith([] { LoadRobotModelFromYaml("/nonexistent.yaml"); }, "/nonexistent.yaml");
  const std::string bad_key = WriteTemp("bad_key.yaml", R"(
name: x
convention: modified_dh
base_link: l0
joints:
  - {name: j1, link: l1, a: 0, d: 0.1, alpha: 0, lower: -1, upper: 1, velocity: 1, acceleraton: 3}
)");
  ExpectThrowsWith([&] { LoadRobotModelFromYaml(bad_key); }, "unknown key 'joints[0].acceleraton'");
  ExpectThrowsWith([&] { LoadRobotModelFromYaml(bad_key); }, bad_key);
  const std::string bad_limits = WriteTemp("bad_limits.yaml", R"(
name: x
convention: modified_dh
base_link: l0
joints:
  - {name: j1, link: l1, a: 0, d: 0.1, alpha: 0, lower: 1, upper: -1, velocity: 1}
)");
  ExpectThrowsWith([&] { LoadRobotModelFromYaml(bad_limits); }, "lower=1 upper=-1");
  // yaml-cpp would keep the first limit and ignore the corrected one.
  const std::string twice = WriteTemp("twice.yaml", R"(
name: x
convention: modified_dh
base_link: l0
joints:
  - {name: j1, link: l1, a: 0, d: 0.1, alpha: 0, lower: -1, upper: 1, velocity: 1, upper: 2}
)");
  ExpectThrowsWith([&] { LoadRobotModelFromYaml(twice); }, twice + ": key 'joints[0].upper': appears twice (lines 6 and 6)");
  const std::string mesh = WriteTemp("mesh.urdf", R"(<robot name="m">
  <link name="a"><collision><geometry><mesh filename="x.stl"/></geometry></collision></link>
</robot>)");
  // A mesh that is not there: the URDF, the link and the file it looked for.
  ExpectThrowsWith([&] { LoadRobotModelFromUrdf(mesh); }, mesh + ": link 'a': ");
  ExpectThrowsWith([&] { LoadRobotModelFromUrdf(mesh); }, "x.stl: cannot read the mesh");
  RobotModelOptions opt;
  opt.ignore_mesh_collisions = true;
  EXPECT_EQ(LoadRobotModelFromUrdf(mesh, opt).spheres.size(), 0u);
  opt.locked_joints["nope"] = 0.0;
  ExpectThrowsWith([&] { LoadRobotModelFromUrdf(kUrdf, opt); }, "locked joint 'nope'");
}

// Any serial arm: continuous and prismatic joints, a fixed tool frame, box
// and cylinder collision shapes, checked against hand-derived kinematics.
TEST(RobotModelTest, ToyArmFromUrdf) {
  const std::string path = WriteTemp("toy.urdf", R"(<robot name="toy">
  <link name="base"/>
  <link name="l1"><collision><origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/>
    <geometry><cylinder radius="0.05" length="0.5"/></geometry></collision></link>
  <link name="l2"><collision><origin xyz="0.1 0 0"/>
    <geometry><box size="0.2 0.1 0.1"/></geometry></collision></link>
  <link name="tool"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.5 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" velocity="0.5" effort="10"/></joint>
  <joint name="j3" type="fixed"><parent link="l2"/><child link="tool"/>
    <origin xyz="0.2 0 0"/></joint>
</robot>)");
  const RobotModel m = LoadRobotModelFromUrdf(path);
  ASSERT_EQ(m.nq, 2);
  EXPECT_EQ(m.link_names.front(), "base");
  const JointLimits& l1 = m.joints[m.q_joints[0]].limits;
  const JointLimits& l2 = m.joints[m.q_joints[1]].limits;
  EXPECT_TRUE(std::isinf(l1.lower) && std::isinf(l1.upper));
  EXPECT_EQ(l2.lower, 0.0);
  EXPECT_EQ(l2.upper, 0.3);
  EXPECT_EQ(l2.velocity, 0.5);
  EXPECT_EQ(l2.acceleration, RobotModelOptions{}.default_acceleration);
  ASSERT_EQ(m.cover_report.size(), 2u);
  EXPECT_EQ(m.cover_report[0].cover.shape, "cylinder");
  EXPECT_EQ(m.cover_report[1].cover.shape, "box");
  RobotData d(m);
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double q1 = 10.0 * (u01(rng) - 0.5), q2 = 0.3 * u01(rng);
    CalcForwardKinematics(m, Eigen::Vector2d(q1, q2), &d);
    const Eigen::Vector3d expected =
        Eigen::Vector3d(0, 0, 0.1) + (0.5 + q2 + 0.2) * Eigen::Vector3d(std::cos(q1), std::sin(q1), 0);
    EXPECT_LE((d.X_WL[m.FindLink("tool")].translation() - expected).norm(), 1e-12);
    // The spheres cover the rod (cylinder along x of l1) and the box of l2.
    std::vector<Sphere> spheres;
    for (size_t i = 0; i < m.spheres.size(); ++i) {
      spheres.push_back({d.p_WS.col(static_cast<Eigen::Index>(i)), m.spheres[i].radius});
    }
    const Eigen::Isometry3d& X_W1 = d.X_WL[m.FindLink("l1")];
    const Eigen::Isometry3d& X_W2 = d.X_WL[m.FindLink("l2")];
    Eigen::Isometry3d X_1C = Eigen::Isometry3d::Identity();
    X_1C.translation() = Eigen::Vector3d(0.25, 0, 0);
    X_1C.linear() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    for (const auto& p : SampleCylinder(0.05, 0.5, 50, &rng)) {
      ASSERT_TRUE(Covered(spheres, X_W1 * X_1C * p, 1e-12));
    }
    for (const auto& p : SampleBox(Eigen::Vector3d(0.1, 0.05, 0.05), 50, &rng)) {
      ASSERT_TRUE(Covered(spheres, X_W2 * (p + Eigen::Vector3d(0.1, 0, 0)), 1e-12));
    }
  }
}

TEST(RobotModelTest, ForwardKinematicsDoesNotAllocate) {
  const RobotModel yaml = LoadRobotModelFromYaml(kYaml);
  RobotData data(yaml);
  const Eigen::VectorXd q = 0.5 * (yaml.LowerLimits() + yaml.UpperLimits());
  test_support::StartCountingAllocations();
  CalcForwardKinematics(yaml, q, &data);
  EXPECT_EQ(test_support::StopCountingAllocations(), 0);
  EXPECT_GT(data.p_WS.cwiseAbs().sum(), 0.0);
}

// Measured states against the limits: inside passes, beyond the limit by less
// than the tolerance passes, a corrupted value is named with joint and limit.
TEST(RobotModelTest, JointPositionsAreCheckedAgainstTheLimits) {
  const RobotModel m = LoadRobotModelFromYaml(kYaml);
  const Eigen::VectorXd lo = m.LowerLimits(), hi = m.UpperLimits();
  EXPECT_EQ(CheckJointPositions(m, 0.5 * (lo + hi), 0.05), std::nullopt);
  EXPECT_EQ(CheckJointPositions(m, lo, 0.0), std::nullopt);  // the limits themselves are inside
  Eigen::VectorXd q = hi;
  q[3] += 0.049;
  EXPECT_EQ(CheckJointPositions(m, q, 0.05), std::nullopt);
  q[3] = 100.0;
  EXPECT_EQ(CheckJointPositions(m, q, 0.05),
            std::string("joint 'panda_joint4' at 100 rad is outside its limits [-3.0718, -0.0698] rad by more than 0.05"));
  q = lo;
  q[0] -= 0.051;
  ASSERT_TRUE(CheckJointPositions(m, q, 0.05).has_value());
  EXPECT_EQ(CheckJointPositions(m, q, 0.05)->rfind("joint 'panda_joint1' at -2.9483 rad", 0), 0u);
  q = lo;
  q[6] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(CheckJointPositions(m, q, 0.05), std::string("joint 'panda_joint7' at nan rad is not finite"));
  EXPECT_EQ(CheckJointPositions(m, Eigen::VectorXd::Zero(6), 0.05),
            std::string("6 joint positions for a robot of 7 joints"));
}

TEST(RobotModelTest, JointVelocitiesAreCheckedAgainstTheLimit) {
  const RobotModel m = LoadRobotModelFromYaml(kYaml);
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(7);
  qd[0] = -2.175 * 1.19;  // panda_joint1: 2.175 rad/s
  EXPECT_EQ(CheckJointVelocities(m, qd, 1.2), std::nullopt);
  qd[0] = -5.0;
  EXPECT_EQ(CheckJointVelocities(m, qd, 1.2),
            std::string("joint 'panda_joint1' at -5 rad/s is beyond 1.2 x its limit 2.175 rad/s"));
}

// Continuous joints have no position limit; prismatic ones are reported in m.
TEST(RobotModelTest, JointLimitCheckOfContinuousAndPrismaticJoints) {
  const std::string path = WriteTemp("toy_limits.urdf", R"(<robot name="toy">
  <link name="base"/><link name="l1"/><link name="l2"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" velocity="0.5" effort="10"/></joint>
</robot>)");
  const RobotModel m = LoadRobotModelFromUrdf(path);
  EXPECT_EQ(CheckJointPositions(m, Eigen::Vector2d(1000.0, 0.3), 0.01), std::nullopt);
  EXPECT_EQ(CheckJointPositions(m, Eigen::Vector2d(0.0, 0.4), 0.01),
            std::string("joint 'j2' at 0.4 m is outside its limits [0, 0.3] m by more than 0.01"));
  EXPECT_EQ(CheckJointVelocities(m, Eigen::Vector2d(1000.0, -0.5), 1.0), std::nullopt);  // j1: no velocity limit
  EXPECT_EQ(CheckJointVelocities(m, Eigen::Vector2d(0.0, 0.6), 1.0),
            std::string("joint 'j2' at 0.6 m/s is beyond 1 x its limit 0.5 m/s"));
}

TEST(RobotModelTest, LockedFingersLeaveSevenJoints) {
  RobotModelOptions opt;
  opt.locked_joints = {{"panda_finger_joint1", 0.02}, {"panda_finger_joint2", 0.02}};
  const RobotModel m = LoadRobotModelFromUrdf(kUrdf, opt);
  EXPECT_EQ(m.nq, 7);
  RobotData d(m);
  CalcForwardKinematics(m, Eigen::VectorXd::Zero(7), &d);
  const Eigen::Vector3d left = d.X_WL[m.FindLink("panda_leftfinger")].translation();
  const Eigen::Vector3d right = d.X_WL[m.FindLink("panda_rightfinger")].translation();
  EXPECT_NEAR((left - right).norm(), 0.04, 1e-12);
}

// LoadRobotModel takes every form a config may name: the DH YAML, a URDF,
// and a URDF overlay whose locked joints and limits apply.
TEST(RobotModelTest, LoadRobotModelTakesYamlUrdfAndOverlay) {
  const RobotModel yaml = LoadRobotModel(kYaml);
  EXPECT_EQ(yaml.nq, 7);
  EXPECT_EQ(yaml.spheres.size(), LoadRobotModelFromYaml(kYaml).spheres.size());
  const RobotModel urdf = LoadRobotModel(kUrdf);
  EXPECT_EQ(urdf.nq, LoadRobotModelFromUrdf(kUrdf).nq);
  EXPECT_EQ(urdf.joints[static_cast<std::size_t>(urdf.q_joints[0])].limits.acceleration,
            RobotModelOptions{}.default_acceleration);

  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("iplan-overlay-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string overlay = (dir / "panda_urdf.yaml").string();
  std::ofstream(overlay) << "urdf: " << std::filesystem::relative(kUrdf, dir).string() << "\n"
                         << "locked_joints: [{name: panda_finger_joint1, value: 0.02}, {name: panda_finger_joint2, value: 0.02}]\n"
                         << "acceleration: 5.0\njerk: 2000.0\n";
  const RobotModel over = LoadRobotModel(overlay);
  EXPECT_EQ(over.nq, 7);
  EXPECT_EQ(over.JointNames(), yaml.JointNames());
  for (const int j : over.q_joints) {
    EXPECT_EQ(over.joints[static_cast<std::size_t>(j)].limits.acceleration, 5.0);
    EXPECT_EQ(over.joints[static_cast<std::size_t>(j)].limits.jerk, 2000.0);
  }
  // The same arm as the DH file: the flange in the same place.
  RobotData dy(yaml), du(over);
  const Eigen::VectorXd q = (Eigen::VectorXd(7) << 0.3, -0.5, 0.2, -2.0, 0.1, 1.8, 0.7).finished();
  CalcForwardKinematics(yaml, q, &dy);
  CalcForwardKinematics(over, q, &du);
  EXPECT_LT((dy.X_WL[static_cast<std::size_t>(yaml.FindLink("panda_link8"))].translation() -
             du.X_WL[static_cast<std::size_t>(over.FindLink("panda_link8"))].translation()).norm(), 1e-6);

  EXPECT_EQ(over.tool_link, "");
  // The tool link the overlay names, checked against the URDF.
  std::ofstream(overlay) << "urdf: " << kUrdf << "\ntool_link: panda_hand\n";
  EXPECT_EQ(LoadRobotModel(overlay).tool_link, "panda_hand");
  std::ofstream(overlay) << "urdf: " << kUrdf << "\ntool_link: panda_gripper\n";
  ExpectThrowsWith([&] { LoadRobotModel(overlay); }, overlay + ": key 'tool_link': ");
  ExpectThrowsWith([&] { LoadRobotModel(overlay); }, "no link 'panda_gripper'");

  // Errors name the file: a missing URDF, an unknown key, a bad limit.
  std::ofstream(overlay) << "urdf: nowhere.urdf\n";
  EXPECT_THROW(LoadRobotModel(overlay), std::runtime_error);
  try {
    LoadRobotModel(overlay);
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("(named by " + overlay + ")"), std::string::npos) << e.what();
  }
  std::ofstream(overlay) << "urdf: " << kUrdf << "\nacceleration: 0\n";
  EXPECT_THROW(LoadRobotModel(overlay), std::runtime_error);
  std::ofstream(overlay) << "urdf: " << kUrdf << "\ntool: x\n";
  EXPECT_THROW(LoadRobotModel(overlay), std::runtime_error);
  EXPECT_THROW(LoadRobotModel((dir / "missing.yaml").string()), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace iplan::collision
