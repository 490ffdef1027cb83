// iplan-cloud: the depth camera's clouds (/iplan/depth/points, sensor frame;
// or its depth images, /iplan/depth/image, unprojected with the calibration
// the camera publishes beside them, /iplan/depth/camera_info) into typed
// outputs in the cell frame: static unknown obstacles as boxes
// (/iplan/obstacles, stable ids) and the points of moving objects, people,
// with the sensor's noise covariance (/iplan/human/points). The stage
// (core/cloud_stage.h): workspace crop, robot self-filter from
// /joint_states and the robot's collision spheres, table plane,
// segmentation, tracking over frames.
#include <chrono>
#include <cstdlib>
#include <deque>
#include <optional>

#include "iplan/adapters/adapters.h"
#include "iplan/adapters/cloud_adapters.h"
#include "services/cloud/core/cloud_stage.h"
#include "services/cloud/core/cloud_settings.h"
#include "iplan/cell/joint_trajectory.h"
#include "iplan/core/params.h"
#include "iplan/framework/service.h"
#include "iplan/msg/check.h"

namespace iplan::cloud_service {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;
using SI = const dds::SampleInfo&;

class CloudService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    std::string pipeline_file;
    const core::Overrides overrides = config.ReadParamsFile("pipeline", "cloud_pipeline.yaml", &pipeline_file);
    CloudSettings settings;
    core::ReadParams(config, &settings);  // every range: CloudSettings::Validate
    if (!config.Problems().empty()) return Result::Ok();  // reported by the configuration check
    CloudStageParams p = settings.StageParams();
    joint_state_timeout_ = settings.joint_state_timeout;
    self_filter_ns_ = static_cast<int64_t>(std::llround(settings.self_filter_time * 1e9));
    frame_id_ = settings.frame_id;
    const std::string& robot_file = settings.robot;
    try {
      if (!overrides.empty()) throw std::runtime_error("--set into " + pipeline_file + " is not supported; edit the file");
      p.pipeline = cloud::LoadCloudParams(pipeline_file);
      std::optional<collision::RobotModel> robot;
      if (!robot_file.empty()) robot = collision::LoadRobotModel(config.ResolvePath(robot_file));
      stage_ = std::make_unique<CloudStage>(p, robot ? &*robot : nullptr);
    } catch (const std::exception& e) {
      return Result::Fail(config.file() + ": key 'cloud': " + e.what());
    }
    joint_names_ = stage_->JointNames();
    obstacles_writer_ = &node.Advertise(framework::topics::Obstacles());
    human_writer_ = &node.Advertise(framework::topics::HumanPoints());
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, SI)>([this, &node](const msg::JointState& m, SI) {
                     OnJointState(node, m);
                   }));
    node.Subscribe(framework::topics::DepthPoints(),
                   std::function<void(const msg::PointCloud2&, SI)>([this, &node](const msg::PointCloud2& m, SI) {
                     OnCloud(node, m);
                   }));
    node.Subscribe(framework::topics::DepthCameraInfo(),
                   std::function<void(const msg::CameraInfo&, SI)>([this, &node](const msg::CameraInfo& m, SI) {
                     OnCameraInfo(node, m);
                   }));
    node.Subscribe(framework::topics::DepthImage(),
                   std::function<void(const msg::Image&, SI)>([this, &node](const msg::Image& m, SI) {
                     OnImage(node, m);
                   }));
    node.SetDiagnosticValue("self_filter", joint_names_.empty() ? "off (no robot)" : "waiting for joint states");
    return Result::Ok();
  }

  Result OnActivate(Node&) override { return Result::Ok(); }
  Result OnDeactivate(Node&) override { return Result::Ok(); }

 private:
  void OnJointState(Node& node, const msg::JointState& m) {
    if (joint_names_.empty()) return;
    std::vector<int> index;
    if (node.CountRejection("joint_states", cell::MapJointNames(m.name, joint_names_, &index))) return;
    if (m.position.size() != m.name.size()) {
      node.CountRejection("joint_states", std::string("position and name sizes differ"));
      return;
    }
    Eigen::VectorXd q(static_cast<Eigen::Index>(index.size()));
    for (std::size_t k = 0; k < index.size(); ++k) q[static_cast<Eigen::Index>(k)] = m.position[static_cast<std::size_t>(index[k])];
    // A second of history, so that a cloud processed late still finds the
    // robot's pose of its own time.
    history_.push_back({msg::ToNanoseconds(m.header.stamp), q});
    while (history_.size() > 1 && history_.back().first - history_.front().first > kHistoryNs) history_.pop_front();
  }

  // The robot's pose at the cloud's stamp: interpolated between the joint
  // states just before and just after it when they are at most kBracketNs
  // apart (a busy executor receives joint states in bursts: the nearest one
  // can be 0.1 s or more away, the arm moving centimetres meanwhile, while
  // its path around the stamp is known on both sides); else the nearest
  // state, if within joint_state_timeout.
  std::optional<Eigen::VectorXd> PoseAt(int64_t stamp, bool count = true) const {
    const std::pair<int64_t, Eigen::VectorXd>* best = nullptr;
    const std::pair<int64_t, Eigen::VectorXd>*before = nullptr, *after = nullptr;
    for (const auto& h : history_) {
      if (!best || std::llabs(h.first - stamp) < std::llabs(best->first - stamp)) best = &h;
      if (h.first <= stamp && (!before || h.first > before->first)) before = &h;
      if (h.first >= stamp && (!after || h.first < after->first)) after = &h;
    }
    if (!best) return std::nullopt;
    if (before && after && after->first > before->first && after->first - before->first <= kBracketNs) {
      const double u = static_cast<double>(stamp - before->first) / static_cast<double>(after->first - before->first);
      if (count && static_cast<double>(std::llabs(best->first - stamp)) * 1e-9 > joint_state_timeout_) ++interpolated_;
      return Eigen::VectorXd((1 - u) * before->second + u * after->second);
    }
    if (static_cast<double>(std::llabs(best->first - stamp)) * 1e-9 <= joint_state_timeout_) return best->second;
    return std::nullopt;
  }

  void OnCloud(Node& node, const msg::PointCloud2& m) {
    const auto t0 = std::chrono::steady_clock::now();
    if (node.CountRejection("depth_points", services::FromPointCloud2(m, &cloud_))) return;
    Process(node, m.header.stamp, t0);
  }

  // The camera's calibration: the intrinsics its next images are unprojected
  // with (a calibration that cannot be used is refused, the last good one
  // kept).
  void OnCameraInfo(Node& node, const msg::CameraInfo& m) {
    cloud::CameraIntrinsics k;
    if (node.CountRejection("camera_info", services::FromCameraInfo(m, &k))) return;
    intrinsics_ = k;
    const std::string text = std::to_string(k.width) + "x" + std::to_string(k.height) + " pixels, fx " +
                             core::ParamText(k.fx) + ", fy " + core::ParamText(k.fy) + ", cx " + core::ParamText(k.cx) +
                             ", cy " + core::ParamText(k.cy);
    if (text == calibration_text_) return;  // the same calibration again, as with every image
    node.log().info("camera calibration: {}", text);
    node.SetDiagnosticValue("camera_info", text);
    calibration_text_ = text;
  }

  // A depth image, unprojected with the camera's latest calibration into the
  // organised cloud a PointCloud2 would have carried; none yet (DDS matches
  // the two topics in any order): not processed, counted.
  void OnImage(Node& node, const msg::Image& m) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!intrinsics_) {
      if (++images_without_info_ == 1) {
        node.log().warn("a depth image came before any camera calibration on {}: not processed (counted in "
                        "depth_images_without_camera_info)",
                        framework::topics::DepthCameraInfo().name);
      }
      node.SetDiagnosticValue("depth_images_without_camera_info", std::to_string(images_without_info_));
      return;
    }
    if (node.CountRejection("depth_image", services::FromDepthImage(m, *intrinsics_, &cloud_))) return;
    node.SetDiagnosticValue("depth_images", std::to_string(++images_));
    Process(node, m.header.stamp, t0);
  }

  // cloud_ (the sensor's frame) taken at `header_stamp`, received at t0.
  void Process(Node& node, const msg::Time& header_stamp, std::chrono::steady_clock::time_point t0) {
    const int64_t stamp = msg::ToNanoseconds(header_stamp);
    // The robot's pose when the cloud was taken: the nearest joint state, if
    // near enough; otherwise no self-filter (the robot's own points then
    // count as a person: cautious, and reported).
    const std::optional<Eigen::VectorXd> q = PoseAt(stamp);
    const bool unfiltered = !joint_names_.empty() && !q;
    if (unfiltered) {
      ++unfiltered_;
      // What the history held: the newest joint state against the cloud's stamp.
      node.SetDiagnosticValue("last_without_self_filter",
                              history_.empty() ? std::string("no joint state in the last second")
                                               : "newest joint state " +
                                                     std::to_string((history_.back().first - stamp) * 1e-9) +
                                                     " s from the cloud's stamp, " + std::to_string(history_.size()) +
                                                     " in the last second");
    }
    // And shortly before and after it (self_filter_time): where the joint
    // states put the robot then, the cloud may have seen it.
    std::vector<Eigen::VectorXd> around;
    if (q && self_filter_ns_ > 0) {
      for (int64_t t : {stamp - self_filter_ns_, stamp + self_filter_ns_})
        if (std::optional<Eigen::VectorXd> qa = PoseAt(t, false)) around.push_back(std::move(*qa));
    }
    const StageOutput out = stage_->Process(&cloud_, q, stamp, around);
    Publish(node, header_stamp, out);
    ++processed_;
    node.SetDiagnosticValue("clouds", std::to_string(processed_));
    node.SetDiagnosticValue("obstacles", std::to_string(out.obstacles.size()));
    node.SetDiagnosticValue("human_points", std::to_string(out.human.size()));
    std::size_t tracked = 0;
    for (int k : out.human.motion_of) tracked += k >= 0;
    node.SetDiagnosticValue("tracked_human_points", std::to_string(tracked));
    node.SetDiagnosticValue("motions", std::to_string(out.human.motions.size()));
    node.SetDiagnosticValue("clusters", std::to_string(out.clusters));
    node.SetDiagnosticValue("table", out.table_found ? std::to_string(out.table_points) + " points" : "not found");
    node.SetDiagnosticValue("clouds_without_self_filter", std::to_string(unfiltered_));
    node.SetDiagnosticValue("clouds_pose_interpolated", std::to_string(interpolated_));
    if (!joint_names_.empty()) node.SetDiagnosticValue("self_filter", out.self_filtered ? "on" : "off (no recent joint state)");
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }

  void Publish(Node& node, const msg::Time& stamp, const StageOutput& out) {
    services::ToObstacles(out.obstacles, stamp, frame_id_, &obstacles_);
    services::ToHumanPoints(out.human, stamp, frame_id_, &human_);
    std::string err;
    if (!obstacles_writer_->Write(obstacles_, &err)) node.log().warn("obstacles not published: {}", err);
    if (!human_writer_->Write(human_, &err)) node.log().warn("human points not published: {}", err);
  }

  std::unique_ptr<CloudStage> stage_;
  std::vector<std::string> joint_names_;
  static constexpr int64_t kHistoryNs = 1000000000;           // 1 s of joint states
  static constexpr int64_t kBracketNs = 600000000;            // 0.6 s: the widest gap interpolated across
  std::deque<std::pair<int64_t, Eigen::VectorXd>> history_;  // (stamp ns, q), oldest first
  double joint_state_timeout_ = 0.2;
  int64_t self_filter_ns_ = 0;
  std::string frame_id_ = "world";
  std::optional<cloud::CameraIntrinsics> intrinsics_;  // the camera's latest usable calibration
  std::string calibration_text_;                       // as logged and in the diagnostics
  uint64_t images_ = 0;  // depth images unprojected (of the clouds processed)
  uint64_t images_without_info_ = 0;  // depth images that came before any calibration
  cloud::Cloud cloud_;
  msg::ObstacleArray obstacles_;
  msg::HumanPoints human_;
  dds::Writer<msg::ObstacleArray>* obstacles_writer_ = nullptr;
  dds::Writer<msg::HumanPoints>* human_writer_ = nullptr;
  uint64_t processed_ = 0, unfiltered_ = 0;
  mutable uint64_t interpolated_ = 0;  // clouds whose pose was interpolated across a gap of joint states
};

}  // namespace
}  // namespace iplan::cloud_service

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv,
      {"cloud", "depth-camera clouds into static obstacles and the person's points (crop, self-filter, table, "
                "segmentation, tracking)"},
      [] { return std::make_unique<iplan::cloud_service::CloudService>(); });
}
