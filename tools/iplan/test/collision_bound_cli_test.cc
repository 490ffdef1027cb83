#include "collision_bound_cli.h"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "iplan/collision/bound.h"

namespace iplan::collision {
namespace {

using nlohmann::json;

std::vector<json> RunLines(const std::string& input, int* failures) {
  std::istringstream in(input);
  std::ostringstream out;
  *failures = RunCollisionBoundJsonLines(in, out);
  std::vector<json> lines;
  std::istringstream result(out.str());
  std::string line;
  while (std::getline(result, line)) lines.push_back(json::parse(line));
  return lines;
}

const char* kGood =
    R"({"b":[0.3,-0.1,0.5],"r_robot":0.12,"mu":[0.6,0.5,1.1],"sigma":[0.01,0.002,0,0.002,0.004,0.001,0,0.001,0.0005],"r_human":0.08})";

TEST(BoundCliTest, MatchesLibraryAndRoundTripsNumbers) {
  int failures = -1;
  const auto lines = RunLines(std::string(kGood) + "\n", &failures);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(failures, 0);
  Eigen::Matrix3d S;
  S << 0.01, 0.002, 0, 0.002, 0.004, 0.001, 0, 0.001, 0.0005;
  FactorizedGaussian g;
  ASSERT_TRUE(FactorizeGaussian(Eigen::Vector3d(0.6, 0.5, 1.1), S, &g));
  const PairBound pb = EvaluatePairBound(g, Eigen::Vector3d(0.3, -0.1, 0.5), 0.2);
  EXPECT_GT(pb.lambda, 0.0);
  EXPECT_EQ(lines[0].at("bound").get<double>(), pb.bound);  // exact round trip
  EXPECT_EQ(lines[0].at("lambda").get<double>(), pb.lambda);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(lines[0].at("x_max")[i].get<double>(), pb.x_max[i]);
}

TEST(BoundCliTest, MeanInsideGivesZeroLambda) {
  int failures = -1;
  const auto lines = RunLines(
      R"({"b":[0,0,0],"r_robot":0.1,"mu":[0.05,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0.1})",
      &failures);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].at("lambda").get<double>(), 0.0);
  EXPECT_EQ(lines[0].at("x_max"), json::parse("[0.05,0,0]"));
  EXPECT_EQ(failures, 0);
}

TEST(BoundCliTest, BadLinesGetErrorsAndTheRestStillRuns) {
  const std::string input = std::string(kGood) + "\n" +                                    // 1
      "{not json\n" +                                                                       // 2
      R"({"b":[0,0,0],"r_robot":0.1,"mu":[1,0,0],"r_human":0.1})" + "\n" +                 // 3
      R"({"b":[0,0],"r_robot":0.1,"mu":[1,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0.1})" + "\n" +  // 4
      R"({"b":[0,0,0],"r_robot":-0.1,"mu":[1,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0.1})" + "\n" +  // 5
      R"({"b":[0,0,0],"r_robot":0.1,"mu":[1,0,0],"sigma":[1,0.5,0,0,1,0,0,0,1],"r_human":0.1})" + "\n" +  // 6
      R"({"b":[0,0,0],"r_robot":0.1,"mu":[1,0,0],"sigma":[1,0,0,0,-1,0,0,0,1],"r_human":0.1})" + "\n" +  // 7
      R"({"b":[0,0,0],"r_robot":0.1,"mu":[1e400,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0.1})" + "\n" +  // 8
      "\n" +                                                                                // 9 (blank)
      R"({"b":[0,0,0],"r_robot":0.1,"mu":[1,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0.1,"x":1})" + "\n" +  // 10
      R"([1,2,3])" + "\n" +                                                                 // 11
      R"({"b":[0,0,"a"],"r_robot":0.1,"mu":[1,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0.1})" + "\n" +  // 12
      R"({"b":[0,0,0],"r_robot":0,"mu":[1,0,0],"sigma":[1,0,0,0,1,0,0,0,1],"r_human":0})" + "\n" +  // 13
      kGood + "\n";                                                                         // 14
  int failures = -1;
  const auto lines = RunLines(input, &failures);
  ASSERT_EQ(lines.size(), 13u);
  EXPECT_EQ(failures, 11);
  const std::vector<std::pair<int, std::string>> expected = {
      {1, "line 2: invalid JSON"},
      {2, "line 3: missing key 'sigma'"},
      {3, "line 4: 'b' must be an array of 3 numbers, got [0,0]"},
      {4, "line 5: 'r_robot' = -0.1 must be >= 0"},
      {5, "line 6: 'sigma' is not symmetric: sigma[0][1] = 0.5 but sigma[1][0] = 0"},
      {6, "line 7: 'sigma' is not positive definite (eigenvalues -1, 1, 1)"},
      {7, "line 8: invalid JSON"},  // 1e400 overflows
      {8, "line 10: unknown key 'x'"},
      {9, "line 11: expected a JSON object"},
      {10, "line 12: 'b[2]' must be a number, got \"a\""},
      {11, "line 13: r_robot + r_human = 0 must be positive"},
  };
  for (const auto& [index, text] : expected) {
    ASSERT_TRUE(lines[index].contains("error")) << index << ": " << lines[index].dump();
    EXPECT_EQ(lines[index]["error"].get<std::string>().rfind(text, 0), 0u)
        << "got: " << lines[index]["error"] << " expected prefix: " << text;
  }
  EXPECT_TRUE(lines[0].contains("bound"));
  EXPECT_EQ(lines[12], lines[0]);  // the last good line still ran, same answer
}

TEST(BoundCliTest, InvalidUtf8IsReportedNotThrown) {
  int failures = -1;
  const auto lines = RunLines("{\"b\":\"\xff\xfe\"}\n", &failures);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(failures, 1);
  EXPECT_EQ(lines[0]["error"].get<std::string>().rfind("line 1: ", 0), 0u);
}

}  // namespace
}  // namespace iplan::collision
