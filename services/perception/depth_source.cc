#include "depth_source.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>

#include "iplan/adapters/cloud_adapters.h"
#include "services/perception/core/depth_camera.h"
#include "iplan/cell/joint_trajectory.h"
#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"
#include "iplan/msg/time.h"
#include "iplan/collision/scene.h"

namespace iplan::perception {
namespace fs = std::filesystem;

struct DepthSource::Impl {
  std::string provider = "none";
  double rate_hz = 30;
  std::string frame_id = "depth_camera";
  // simulated
  std::unique_ptr<SimulatedDepthCamera> camera;
  DepthScene fixed;  // the scene files' objects
  DepthScene added;  // the added_scenes files' objects, rendered from added_after s after activation on
  double added_after = 0;  // s
  double human_after = 0;  // s after activation before the person is rendered (they walk into view then)
  std::chrono::steady_clock::time_point activated;
  std::unique_ptr<collision::HumanBodyModel> body;
  std::unique_ptr<collision::RobotModel> robot;
  std::unique_ptr<collision::RobotData> robot_data;
  std::vector<std::string> robot_joints;
  std::optional<Eigen::VectorXd> q;
  // pcd
  std::vector<std::string> files;
  bool loop = true;
  std::size_t next_file = 0;

  TruthFn truth;
  dds::Writer<msg::PointCloud2>* writer = nullptr;
  dds::Writer<msg::Image>* image_writer = nullptr;  // set for transport image (then `writer` is not)
  dds::Writer<msg::CameraInfo>* info_writer = nullptr;  // the image's calibration, beside each image
  int timer = 0;
  uint64_t published = 0;
  cloud::Cloud cloud;
  msg::PointCloud2 message;
  msg::Image image_message;
  msg::CameraInfo info_message;
  double render_ms_sum = 0;

  framework::Result ConfigureSimulated(const framework::ConfigSection& config, const SimulatedDepthSettings& sim);
  framework::Result ConfigurePcd(const framework::ConfigSection& config, const PcdSettings& pcd);
  void OnJointState(framework::Node& node, const msg::JointState& m);
  Eigen::VectorXd RobotNow() const;
  Eigen::VectorXd q_velocity;  // rad/s, of the latest joint state (zero when it carries none)
  int64_t q_stamp_ns = 0;
  bool Produce(framework::Node& node);
  void Tick(framework::Node& node);
};

DepthSource::DepthSource() : impl_(std::make_unique<Impl>()) {}
DepthSource::~DepthSource() = default;

framework::Result DepthSource::Configure(const framework::ConfigSection& config, const DepthSettings& settings,
                                         framework::Node& node) {
  Impl& s = *impl_;
  s.provider = settings.provider;
  s.rate_hz = settings.rate_hz;
  s.frame_id = settings.frame_id;
  framework::Result r = framework::Result::Ok();
  if (s.provider == "simulated") r = s.ConfigureSimulated(config, settings.simulated);
  if (s.provider == "pcd") r = s.ConfigurePcd(config, settings.pcd);
  if (!r.ok || s.provider == "none") return r;
  if (settings.transport == "image") {
    s.image_writer = &node.Advertise(framework::topics::DepthImage());
    s.info_writer = &node.Advertise(framework::topics::DepthCameraInfo());
  } else {
    s.writer = &node.Advertise(framework::topics::DepthPoints());
  }
  if (s.provider == "simulated" && s.robot) {
    using SI = const dds::SampleInfo&;
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, SI)>(
                       [this, &node](const msg::JointState& m, SI) { impl_->OnJointState(node, m); }),
                   framework::SubscribeOptions{false});
  }
  node.SetDiagnosticValue("depth_provider", s.provider);
  return framework::Result::Ok();
}

framework::Result DepthSource::Impl::ConfigureSimulated(const framework::ConfigSection& config,
                                                        const SimulatedDepthSettings& sim) {
  added_after = sim.added_after;
  human_after = sim.human_after;
  try {
    camera = std::make_unique<SimulatedDepthCamera>(sim.Camera());
    auto load = [&config](const std::vector<std::string>& files, DepthScene* into) {
      for (const std::string& f : files) {
        for (const collision::SceneObject& o : collision::LoadSceneParams(config.ResolvePath(f)).objects) {
          if (o.shape == collision::SceneObject::Shape::kBox) {
            into->boxes.push_back({o.X_WO, o.size});
          } else {
            into->cylinders.push_back({o.X_WO, o.radius, o.length});
          }
        }
      }
    };
    load(sim.scenes, &fixed);
    load(sim.added_scenes, &added);
    if (!sim.human_body.empty()) {
      body = std::make_unique<collision::HumanBodyModel>(collision::LoadHumanBodyParams(config.ResolvePath(sim.human_body)));
    }
    if (!sim.robot.empty()) {
      robot = std::make_unique<collision::RobotModel>(collision::LoadRobotModel(config.ResolvePath(sim.robot)));
      robot_data = std::make_unique<collision::RobotData>(*robot);
      robot_joints = robot->JointNames();
    }
  } catch (const std::exception& e) {
    return framework::Result::Fail(config.file() + ": key 'perception.depth.simulated': " + e.what());
  }
  return framework::Result::Ok();
}

framework::Result DepthSource::Impl::ConfigurePcd(const framework::ConfigSection& config, const PcdSettings& pcd) {
  loop = pcd.loop;
  const std::string path = config.ResolvePath(pcd.path);
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const auto& e : fs::directory_iterator(path, ec)) {
      if (e.path().extension() == ".pcd") files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());
  } else if (fs::is_regular_file(path, ec)) {
    files.push_back(path);
  }
  if (files.empty()) {
    return framework::Result::Fail(config.file() + ": key 'perception.depth.pcd.path': no .pcd file at " + path);
  }
  try {
    cloud::LoadPcd(files.front());  // a broken first file is a configuration problem, found now
  } catch (const std::exception& e) {
    return framework::Result::Fail(config.file() + ": key 'perception.depth.pcd.path': " + e.what());
  }
  return framework::Result::Ok();
}

void DepthSource::Impl::OnJointState(framework::Node& node, const msg::JointState& m) {
  std::vector<int> index;
  if (node.CountRejection("joint_states", cell::MapJointNames(m.name, robot_joints, &index))) return;
  if (m.position.size() != m.name.size()) return;
  Eigen::VectorXd v(static_cast<Eigen::Index>(index.size()));
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(v.size());
  for (std::size_t k = 0; k < index.size(); ++k) {
    v[static_cast<Eigen::Index>(k)] = m.position[static_cast<std::size_t>(index[k])];
    if (m.velocity.size() == m.name.size()) qd[static_cast<Eigen::Index>(k)] = m.velocity[static_cast<std::size_t>(index[k])];
  }
  q = v;
  q_velocity = qd;
  q_stamp_ns = msg::ToNanoseconds(m.header.stamp);
}

// The robot where it is now, as a camera would capture it: the latest joint
// state moved on at its velocity for the time since its stamp (at most
// kMaxExtrapolation: a late joint state is not a trajectory). Rendering the
// latest state as it is put the robot where it was up to a few hundred ms
// ago on a loaded host, and the cloud service's self-filter, at the pose of
// the cloud's stamp, then left slivers of the arm as "human" points.
Eigen::VectorXd DepthSource::Impl::RobotNow() const {
  constexpr double kMaxExtrapolation = 0.3;  // s
  const double age = std::clamp((msg::ToNanoseconds(msg::Now()) - q_stamp_ns) * 1e-9, 0.0, kMaxExtrapolation);
  return *q + age * q_velocity;
}

// One frame into `cloud`; false when there is nothing (more) to publish.
bool DepthSource::Impl::Produce(framework::Node& node) {
  if (provider == "pcd") {
    if (next_file >= files.size()) {
      if (!loop) return false;
      next_file = 0;
    }
    const std::string& f = files[next_file++];
    try {
      cloud = cloud::LoadPcd(f);
    } catch (const std::exception& e) {
      node.CountRejection("pcd_file", std::string(e.what()));
      return false;
    }
    return true;
  }
  DepthScene scene = fixed;
  const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - activated).count();
  if (since >= added_after) {
    scene.boxes.insert(scene.boxes.end(), added.boxes.begin(), added.boxes.end());
    scene.cylinders.insert(scene.cylinders.end(), added.cylinders.begin(), added.cylinders.end());
  }
  if (body && truth && since >= human_after) {
    const std::vector<double> radii = body->Radii();
    Eigen::Matrix3Xd J(3, body->num_joints());
    for (const std::vector<JointSample>& joints : truth()) {
      bool complete = !joints.empty();
      for (int j = 0; j < body->num_joints() && complete; ++j) {
        const std::string& name = body->params().joints[static_cast<std::size_t>(j)];
        auto it = std::find_if(joints.begin(), joints.end(), [&](const JointSample& s) { return s.name == name; });
        if (it == joints.end()) complete = false; else J.col(j) = it->position_W;
      }
      for (int k = 0; complete && k < body->num_spheres(); ++k) {
        scene.spheres.push_back({body->SphereCentre(k, J), radii[static_cast<std::size_t>(k)]});
      }
    }
  }
  if (robot && q && q->size() == robot->nq) {
    collision::CalcForwardKinematics(*robot, RobotNow(), robot_data.get());
    for (std::size_t k = 0; k < robot->spheres.size(); ++k) {
      scene.spheres.push_back({robot_data->p_WS.col(static_cast<Eigen::Index>(k)), robot->spheres[k].radius});
    }
  }
  camera->Render(scene, &cloud);
  return true;
}

void DepthSource::Impl::Tick(framework::Node& node) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!Produce(node)) return;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::string err;
  if (image_writer) {  // transport image: a depth image and its calibration instead of the cloud
    const msg::Time stamp = msg::Now();
    services::ToDepthImage(cloud, stamp, frame_id, &image_message);
    services::ToCameraInfo(camera->params().intrinsics, stamp, frame_id, &info_message);
    if (!info_writer->Write(info_message, &err)) node.log().warn("camera info not published: {}", err);
    if (!image_writer->Write(image_message, &err)) node.log().warn("depth image not published: {}", err);
  } else {
    services::ToPointCloud2(cloud, msg::Now(), frame_id, &message);
    if (!writer->Write(message, &err)) node.log().warn("cloud not published: {}", err);
  }
  ++published;
  render_ms_sum += ms;
  node.SetDiagnosticValue("clouds_published", std::to_string(published));
  node.SetDiagnosticValue("depth_frame_ms_mean", std::to_string(render_ms_sum / static_cast<double>(published)));
}

void DepthSource::Activate(framework::Node& node, TruthFn truth) {
  Impl& s = *impl_;
  if (s.provider == "none") return;
  s.truth = std::move(truth);
  s.activated = std::chrono::steady_clock::now();
  s.timer = node.AddTimer(std::chrono::nanoseconds(static_cast<int64_t>(1e9 / s.rate_hz)), [this, &node] { impl_->Tick(node); });
}

void DepthSource::Deactivate(framework::Node& node) {
  if (impl_->provider != "none") node.CancelTimer(impl_->timer);
}

}  // namespace iplan::perception
