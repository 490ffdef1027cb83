// `iplan intent train` as a process on a one-joint recording (the right
// wrist of UTKinect, cut from ../shared/data): with no joint flags it trains
// on the joint the data has, and `iplan intent eval` evaluates the model on
// a subject it did not see.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_paths.h"

namespace iplan::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// The CSV's columns `keep` (by name), every row.
void CutColumns(const std::string& in_path, const std::vector<std::string>& keep, const std::string& out_path) {
  std::ifstream in(in_path);
  ASSERT_TRUE(in.good()) << in_path;
  std::ofstream out(out_path);
  std::vector<std::size_t> idx;
  bool header = true;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (header) {
      for (const auto& k : keep) {
        const auto it = std::find(cells.begin(), cells.end(), k);
        ASSERT_NE(it, cells.end()) << "no column " << k;
        idx.push_back(static_cast<std::size_t>(it - cells.begin()));
      }
      header = false;
    }
    for (std::size_t i = 0; i < idx.size(); ++i) out << (i ? "," : "") << cells.at(idx[i]);
    out << "\n";
  }
}

TEST(IntentCli, TrainsOnAOneJointRecordingWithoutJointFlags) {
  const fs::path dir = fs::temp_directory_path() / ("iplan-intent-cli-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string data = (dir / "wrist.csv").string(), model = (dir / "wrist.model").string();
  CutColumns(std::string(IPLAN_SHARED_DIR) + "/data/utkinect.csv",
             {"sequence", "subject", "action", "frame", "time", "wrist_r.x", "wrist_r.y", "wrist_r.z"}, data);
  // Small settings: this is about the joint set, not about the figures.
  Process train({BinPath("iplan"), "intent", "train", "--data", data, "--subjects", "s01,s02,s03", "--out", model,
                 "--gp-iterations", "15", "--max-forecast-windows", "60", "--pseudo-inputs", "10"});
  const auto rc = train.Wait(300s);
  ASSERT_TRUE(rc.has_value()) << "train did not finish\n" << train.Stdout();
  ASSERT_EQ(*rc, 0) << train.Stdout() << train.Stderr();
  const std::string out = train.Stdout();
  EXPECT_NE(out.find("joints: wrist_r\n"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(model));

  Process eval({BinPath("iplan"), "intent", "eval", "--model", model, "--data", data, "--subjects", "s09", "--json"});
  const auto erc = eval.Wait(120s);
  ASSERT_TRUE(erc.has_value());
  ASSERT_EQ(*erc, 0) << eval.Stdout() << eval.Stderr();
  const nlohmann::json j = nlohmann::json::parse(eval.Stdout());
  std::cout << "held-out s09, one joint: " << j.dump().substr(0, 400) << "\n";
  // Ten actions: far above chance (0.1) on the whole sequences of the unseen subject.
  EXPECT_GT(j["accuracy"]["1.0"].get<double>(), 0.5);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace iplan::testing
