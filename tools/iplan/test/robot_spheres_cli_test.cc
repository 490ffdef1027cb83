// `iplan robot spheres` on the UR5e's real meshes and the Panda's
// primitives: the JSON fields the issue names, the cache, bad input.
#include "robot_spheres_cli.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace iplan::collision {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kShared = IPLAN_SHARED_DIR;

class RobotSpheresCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("iplan_robot_spheres_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ::setenv("IPLAN_CACHE_DIR", dir_.c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("IPLAN_CACHE_DIR");
    fs::remove_all(dir_);
  }
  json Run(RobotSpheresOptions o, int expected_code) {
    std::ostringstream out, err;
    o.json = true;
    EXPECT_EQ(RunRobotSpheres(o, out, err), expected_code) << err.str();
    return json::parse(out.str());
  }
  fs::path dir_;
};

TEST_F(RobotSpheresCliTest, Ur5eEveryVertexCoveredAndTheExcessStated) {
  RobotSpheresOptions o;
  o.robot = kShared + "/robots/ur5e/ur5e.urdf";
  o.out = (dir_ / "cover.json").string();
  const json first = Run(o, 0);
  ASSERT_EQ(first["links"].size(), 7u);
  for (const json& l : first["links"]) {
    EXPECT_EQ(l["uncovered_vertices"], 0) << l["link"];
    EXPECT_GT(l["spheres"].get<int>(), 0) << l["link"];
    EXPECT_LE(l["max_excess_m"].get<double>(), 0.025 + 1e-12) << l["link"];
    EXPECT_LE(l["sampled_excess_m"].get<double>(), l["max_excess_m"].get<double>() + 1e-9) << l["link"];
    EXPECT_FALSE(l["from_cache"].get<bool>()) << l["link"];
    EXPECT_EQ(l["mesh_files"].size(), 1u);
  }
  EXPECT_LE(first["median_max_excess_m"].get<double>(), 0.025);
  EXPECT_EQ(first["uncovered_vertices"], 0);
  // Self-collision pairs by sampling: the six joints' neighbours skipped as
  // adjacent, every one of the 21 pairs of the 7 links accounted for.
  const json& self = first["self_collision"];
  int adjacent = 0;
  for (const json& p : self["skipped"]) adjacent += p["reason"] == "adjacent" ? 1 : 0;
  EXPECT_EQ(adjacent, 6);
  EXPECT_EQ(self["checked"].size() + self["skipped"].size(), 21u);
  // The written cover holds every sphere.
  std::ifstream f(o.out);
  const json cover = json::parse(f);
  EXPECT_EQ(cover["spheres"].size(), first["total_spheres"].get<std::size_t>());
  // Again: every mesh from the cache, the same numbers.
  o.out.clear();
  const json second = Run(o, 0);
  for (const json& l : second["links"]) EXPECT_TRUE(l["from_cache"].get<bool>()) << l["link"];
  EXPECT_EQ(second["total_spheres"], first["total_spheres"]);
  EXPECT_EQ(second["median_max_excess_m"], first["median_max_excess_m"]);
}

TEST_F(RobotSpheresCliTest, PandaPrimitivesAndBadInput) {
  RobotSpheresOptions o;
  o.robot = kShared + "/robots/panda/panda_collision.urdf";
  const json panda = Run(o, 0);
  EXPECT_GE(panda["links"].size(), 8u);
  for (const json& l : panda["links"]) EXPECT_TRUE(l["mesh_files"].empty()) << l["link"];

  std::ostringstream out, err;
  o.robot = (dir_ / "missing.urdf").string();
  EXPECT_EQ(RunRobotSpheres(o, out, err), 2);
  EXPECT_NE(err.str().find("missing.urdf"), std::string::npos) << err.str();

  // A URDF whose mesh is not there names the link and the file it looked for.
  const std::string urdf = (dir_ / "arm.urdf").string();
  std::ofstream(urdf) << "<robot name=\"arm\"><link name=\"base\"><collision><geometry>"
                         "<mesh filename=\"meshes/none.stl\"/></geometry></collision></link></robot>\n";
  std::ostringstream out2, err2;
  o.robot = urdf;
  EXPECT_EQ(RunRobotSpheres(o, out2, err2), 2);
  EXPECT_NE(err2.str().find("link 'base'"), std::string::npos) << err2.str();
  EXPECT_NE(err2.str().find("none.stl"), std::string::npos) << err2.str();
}

}  // namespace
}  // namespace iplan::collision
