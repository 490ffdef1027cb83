// `iplan cloud obstacles` as a process on a shared mOSD scan: --json prints
// exactly one line with the documented fields, --labels-out writes one label
// per input point that agrees with it, --config is loaded strictly, and bad
// requests exit with code 2 naming the problem. `iplan cloud eval` on two
// scans, with and without cross-validating a grid.
#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "iplan/core/atomic_file.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const std::string kScan = std::string(IPLAN_SHARED_DIR) + "/data/pointclouds/mosd_learn/learn0.pcd";

class CloudCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("iplan-cloud-cli-" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  int Run(const std::vector<std::string>& args, std::string* out, std::string* err) {
    std::vector<std::string> argv = {BinPath("iplan"), "cloud"};
    argv.insert(argv.end(), args.begin(), args.end());
    Process p(argv);
    const auto rc = p.Wait(60s);
    *out = p.Stdout();
    *err = p.Stderr();
    return rc.value_or(-1);
  }

  fs::path dir_;
};

TEST_F(CloudCli, JsonLineAndLabelsAgree) {
  const std::string labels_path = (dir_ / "labels.txt").string();
  std::string out, err;
  ASSERT_EQ(Run({"obstacles", "--pcd", kScan, "--json", "--labels-out", labels_path}, &out, &err), 0) << err;
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find('\n'), out.size() - 1) << "more than one line: " << out;
  EXPECT_EQ(out.rfind("{\"table\":{\"normal\":[", 0), 0u) << out;  // keys in the documented order
  EXPECT_NE(out.find("],\"offset\":"), std::string::npos) << out;
  EXPECT_NE(out.find("},\"obstacles\":[{\"id\":1,\"centre\":["), std::string::npos) << out;
  EXPECT_NE(out.find("],\"half_extents\":["), std::string::npos) << out;
  EXPECT_NE(out.find("}],\"time_s\":"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j.size(), 3u) << out;
  ASSERT_TRUE(j.contains("table") && j.contains("obstacles") && j.contains("time_s")) << out;
  EXPECT_EQ(j["table"].size(), 3u);
  EXPECT_EQ(j["table"]["normal"].size(), 3u);
  double norm2 = 0;
  for (const auto& v : j["table"]["normal"]) norm2 += v.get<double>() * v.get<double>();
  EXPECT_NEAR(norm2, 1.0, 1e-5);
  EXPECT_GT(j["table"]["offset"].get<double>(), 0.0);
  EXPECT_GT(j["time_s"].get<double>(), 0.0);

  std::ifstream in(labels_path);
  std::map<int, long> count;
  std::string line;
  long lines = 0;
  while (std::getline(in, line)) {
    ++lines;
    ++count[std::stoi(line)];
  }
  EXPECT_EQ(lines, 640 * 480);
  EXPECT_EQ(count[1], j["table"]["points"].get<long>());
  const auto& obstacles = j["obstacles"];
  ASSERT_EQ(obstacles.size(), 2u) << out;  // learn0: two boxes
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const auto& o = obstacles[k];
    EXPECT_EQ(o.size(), 6u);
    EXPECT_EQ(o["id"].get<int>(), static_cast<int>(k) + 1);
    EXPECT_EQ(o["centre"].size(), 3u);
    EXPECT_EQ(o["half_extents"].size(), 3u);
    ASSERT_EQ(o["orientation"].size(), 4u);  // x, y, z, w of a unit quaternion
    double q2 = 0;
    for (const auto& v : o["orientation"]) q2 += v.get<double>() * v.get<double>();
    EXPECT_NEAR(q2, 1.0, 1e-5);
    EXPECT_EQ(o["group"].get<int>(), static_cast<int>(k) + 1);  // two boxes apart: two groups
    EXPECT_EQ(count[o["id"].get<int>() + 1], o["points"].get<long>());
    EXPECT_GT(o["centre"][2].get<double>(), 0.3);  // in front of the camera, metres
  }
  long listed = count[0] + count[1];
  for (const auto& o : obstacles) listed += o["points"].get<long>();
  EXPECT_EQ(listed, lines);  // no label outside 0, 1 and the obstacles
}

TEST_F(CloudCli, TextOutputAndConfigFileOfTheRepository) {
  std::string out, err;
  ASSERT_EQ(Run({"obstacles", "--pcd", kScan, "--config", std::string(IPLAN_SOURCE_DIR) + "/config/cloud_pipeline.yaml"},
                &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("2 obstacles (sensor frame, m):"), std::string::npos) << out;
  EXPECT_NE(out.find("table: normal ["), std::string::npos) << out;
}

TEST_F(CloudCli, RefusesBadRequestsWithExitCodeTwo) {
  std::string out, err;
  const std::string bad = (dir_ / "bad.yaml").string();
  core::WriteFileAtomically(bad, "stride: 2\nvoxle_size: 0.01\n");
  EXPECT_EQ(Run({"obstacles", "--pcd", kScan, "--config", bad}, &out, &err), 2);
  EXPECT_NE(err.find(bad + ": unknown key 'voxle_size'"), std::string::npos) << err;
  EXPECT_EQ(Run({"obstacles", "--pcd", (dir_ / "missing.pcd").string()}, &out, &err), 2);
  EXPECT_NE(err.find("missing.pcd: cannot read PCD file"), std::string::npos) << err;
  const std::string garbage = (dir_ / "garbage.pcd").string();
  core::WriteFileAtomically(garbage, "this is no point cloud\n");
  EXPECT_EQ(Run({"obstacles", "--pcd", garbage}, &out, &err), 2);
  EXPECT_NE(err.find("garbage.pcd: "), std::string::npos) << err;
  EXPECT_NE(Run({"obstacles"}, &out, &err), 0);  // --pcd is required
  EXPECT_NE(err.find("--pcd is required"), std::string::npos) << err;
  ASSERT_EQ(Run({"obstacles", "--help"}, &out, &err), 0);
  EXPECT_NE(out.find("--labels-out"), std::string::npos) << out;
}

// `iplan cloud eval` on a folder of two labelled scans (learn0, learn17),
// then with a grid of two settings cross-validated scene by scene: the
// table rows, the totals, each fold's choice and the cross-validated line.
TEST_F(CloudCli, EvalScoresBothPipelinesAndCrossValidatesAGrid) {
  const fs::path scans = dir_ / "scans";
  fs::create_directories(scans);
  for (const char* name : {"learn0.pcd", "learn17.pcd"})
    fs::create_symlink(fs::path(IPLAN_SHARED_DIR) / "data/pointclouds/mosd_learn" / name, scans / name);
  std::string out, err;
  ASSERT_EQ(Run({"eval", "--dir", scans.string()}, &out, &err), 0) << err;
  // learn0: two boxes apart, both pipelines find both; learn17: a box on a
  // box, only ours splits them (the textbook's Euclidean clusters cannot).
  EXPECT_NE(out.find("| learn0 | 2 | 2 | 2 | 0 |"), std::string::npos) << out;
  EXPECT_NE(out.find("| learn17 | 2 | 2 | 2 | 0 |"), std::string::npos) << out;
  EXPECT_NE(out.find("| total | 4 | 4 | 4 | 0 |"), std::string::npos) << out;
  EXPECT_NE(out.find("ours: recall 100.0 % (4/4), false obstacles 0.00 per scene"), std::string::npos) << out;
  EXPECT_NE(out.find("textbook: recall 50.0 % (2/4)"), std::string::npos) << out;
  EXPECT_EQ(out.find("cross-validation"), std::string::npos) << out;

  // Two settings: the default and one without crease cues (which cannot
  // split the stack). Each scene held out in turn: the other scene alone
  // chooses; learn0 cannot tell them apart (the earlier, default, wins),
  // learn17 chooses the default.
  const std::string grid = (dir_ / "grid.yaml").string();
  core::WriteFileAtomically(grid, "concave_margin: [0.1, 2.0]\nstep_angle_deg: 30\n");
  ASSERT_EQ(Run({"eval", "--dir", scans.string(), "--cv", grid}, &out, &err), 0) << err;
  EXPECT_NE(out.find("cross-validation: 2 settings"), std::string::npos) << out;
  EXPECT_NE(out.find("| learn0 | concave_margin=0.1 step_angle_deg=30 | 2 | 2 | 0 |"), std::string::npos) << out;
  EXPECT_NE(out.find("| learn17 | concave_margin=0.1 step_angle_deg=30 | 2 | 2 | 0 |"), std::string::npos) << out;
  EXPECT_NE(out.find("cross-validated: recall 100.0 % (4/4), false obstacles 0.00 per scene"), std::string::npos)
      << out;
  EXPECT_NE(out.find("chosen on all scenes (tuned on them): concave_margin=0.1 step_angle_deg=30: recall 100.0 %"),
            std::string::npos)
      << out;
  // With the crease cues first in the list and both scenes one fold, the
  // fold has no other scene to choose on: the first setting is taken.
  core::WriteFileAtomically(grid, "concave_margin: [2.0, 0.1]\nstep_angle_deg: [90]\n");
  ASSERT_EQ(Run({"eval", "--dir", scans.string(), "--cv", grid, "--cv-fold", "learn0 learn17"}, &out, &err), 0)
      << err;
  EXPECT_NE(out.find("| learn0 learn17 | concave_margin=2.0 step_angle_deg=90 | 4 | 2 | 1 |"), std::string::npos)
      << out;

  // Bad grids and folds: exit code 2 naming the problem.
  core::WriteFileAtomically(grid, "concave_margn: [0.1]\n");
  EXPECT_EQ(Run({"eval", "--dir", scans.string(), "--cv", grid}, &out, &err), 2);
  EXPECT_NE(err.find(grid + ": unknown key 'concave_margn'"), std::string::npos) << err;
  core::WriteFileAtomically(grid, "stride: [2, 0]\n");
  EXPECT_EQ(Run({"eval", "--dir", scans.string(), "--cv", grid}, &out, &err), 2);
  EXPECT_NE(err.find("stride=0: stride must be in 1..8, got 0"), std::string::npos) << err;
  core::WriteFileAtomically(grid, "stride: [2]\n");
  EXPECT_EQ(Run({"eval", "--dir", scans.string(), "--cv", grid, "--cv-fold", "learn5"}, &out, &err), 2);
  EXPECT_NE(err.find("--cv-fold: no scene 'learn5' in the folder"), std::string::npos) << err;
  EXPECT_NE(Run({"eval", "--dir", scans.string(), "--cv-fold", "learn0"}, &out, &err), 0);  // needs --cv
}

}  // namespace
}  // namespace iplan::testing
