// The iplan tool against a real service on the other vendor: topic list sees
// the service's writers, echo prints its skeletons as JSON, hz measures its
// rate, and pub delivers a message a service-side reader checks.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>
#include <thread>

#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;

class IplanTopic : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = std::to_string(UniqueDomain(31));
    svc_ = std::make_unique<Process>(
        std::vector<std::string>{BinPath("iplan-perception"), "--dds", "fastdds", "--domain", domain_});
  }
  std::unique_ptr<Process> Tool(std::vector<std::string> args) {
    args.insert(args.begin(), BinPath("iplan"));
    args.insert(args.end(), {"--dds", "cyclonedds", "--domain", domain_});
    return std::make_unique<Process>(args);
  }
  std::string domain_;
  std::unique_ptr<Process> svc_;
};

TEST_F(IplanTopic, EchoPrintsSkeletonsAsJson) {
  auto echo = Tool({"topic", "echo", "/iplan/human/skeleton", "-n", "3", "--timeout", "20"});
  ASSERT_EQ(echo->Wait(30s), 0) << echo->Stderr();
  std::istringstream lines(echo->Stdout());
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["joints"].size(), 9u);
    EXPECT_EQ(j["header"]["frame_id"], "world");
    ++n;
  }
  EXPECT_EQ(n, 3);
}

TEST_F(IplanTopic, ListShowsTheServiceWriters) {
  auto list = Tool({"topic", "list", "--wait", "3"});
  ASSERT_EQ(list->Wait(30s), 0) << list->Stderr();
  const std::string out = list->Stdout();
  // The skeleton line: topic, writers, readers, type (columns padded to the longest name).
  std::istringstream lines(out);
  std::string line, topic, type;
  int writers = -1, readers = -1;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    fields >> topic;
    if (topic == "/iplan/human/skeleton") {
      fields >> writers >> readers >> type;
      break;
    }
  }
  EXPECT_EQ(writers, 1) << out;
  EXPECT_EQ(readers, 0) << out;
  EXPECT_EQ(type, "iplan_msgs::msg::dds_::HumanSkeleton_") << out;
  EXPECT_NE(out.find("/diagnostics"), std::string::npos) << out;
}

TEST_F(IplanTopic, HzMeasuresThirtyHertz) {
  auto hz = Tool({"topic", "hz", "/iplan/human/skeleton", "--duration", "4"});
  ASSERT_EQ(hz->Wait(30s), 0) << hz->Stderr();
  const std::string out = hz->Stdout();
  const auto pos = out.rfind("average rate: ");
  ASSERT_NE(pos, std::string::npos) << out;
  EXPECT_NEAR(std::stod(out.substr(pos + 14)), 30.0, 3.0) << out;
}

TEST_F(IplanTopic, UnknownTopicWithoutTypeIsAClearError) {
  auto echo = Tool({"topic", "echo", "/nobody/publishes/this", "--timeout", "2"});
  ASSERT_EQ(echo->Wait(30s), 1);
  EXPECT_NE(echo->Stderr().find("is not an iplan topic and nobody publishes it; give --type"), std::string::npos)
      << echo->Stderr();
}

TEST_F(IplanTopic, PubDeliversAMessageToEcho) {
  auto echo = Tool({"topic", "echo", "/iplan/safety/permit/supervisor", "-n", "1", "--timeout", "40"});
  std::this_thread::sleep_for(1s);
  // The echo's reader may take seconds to appear beside three other tests
  // on two cores; the permit topic is volatile, so publish once it has.
  auto pub = Tool({"topic", "pub", "/iplan/safety/permit/supervisor",
                   R"({"state": 0, "validity": 0.2, "source": "test", "reason": "operator", "seq": 7})", "--stamp-now",
                   "--wait-readers", "20"});
  ASSERT_EQ(pub->Wait(30s), 0) << pub->Stderr();
  EXPECT_EQ(pub->Stderr().find("no reader"), std::string::npos) << pub->Stderr();
  ASSERT_EQ(echo->Wait(60s), 0) << echo->Stderr() << "pub:\n" << pub->Stdout() << pub->Stderr();
  const auto j = nlohmann::json::parse(echo->Stdout());
  EXPECT_EQ(j["seq"], 7);
  EXPECT_EQ(j["reason"], "operator");
  EXPECT_GT(j["header"]["stamp"]["sec"].get<int>(), 1700000000);
  auto bad = Tool({"topic", "pub", "/iplan/safety/permit/supervisor", R"({"stat": 0})"});
  ASSERT_EQ(bad->Wait(30s), 1);
  EXPECT_NE(bad->Stderr().find("unknown field 'stat'"), std::string::npos) << bad->Stderr();
  // Nobody reads the collision-risk permit here: published, and said so.
  auto lonely = Tool({"topic", "pub", "/iplan/safety/permit/collision_risk",
                      R"({"state": 0, "validity": 0.2, "source": "test", "reason": "operator", "seq": 8})",
                      "--wait-readers", "0.5"});
  ASSERT_EQ(lonely->Wait(30s), 0) << lonely->Stderr();
  EXPECT_NE(lonely->Stderr().find("no reader of /iplan/safety/permit/collision_risk matched within 0.5 s"),
            std::string::npos)
      << lonely->Stderr();
}

}  // namespace
}  // namespace iplan::testing
