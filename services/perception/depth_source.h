// Perception's depth providers, publishing sensor_msgs/PointCloud2 on
// /iplan/depth/points in the camera's optical frame (frame_id from the
// configuration):
//   - "simulated": the simulated depth camera (core/depth_camera.h)
//     rendering the scene files' boxes and cylinders (the table, the parts
//     bin, ...), the synthetic person's true body spheres (HumanBodyModel)
//     and the robot's collision spheres at its latest /joint_states;
//   - "pcd": recorded PCD files (one file, or every .pcd of a folder in name
//     order) at a rate, looping or not;
//   - "none" (default): no clouds.
// Section perception.depth of perception.yaml; docs/perception-clouds.md.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "services/perception/core/synthetic_person.h"
#include "perception_settings.h"
#include "iplan/framework/service.h"

namespace iplan::perception {

class DepthSource {
 public:
  /// The true pose of every simulated person now, one joint list per
  /// person (empty: nobody).
  using TruthFn = std::function<std::vector<std::vector<JointSample>>()>;

  DepthSource();
  ~DepthSource();

  /// Loads what the provider of `settings` (perception.depth, read and
  /// checked) needs, with paths relative to `config`'s file, and advertises
  /// the cloud topic. A file that cannot be loaded fails, naming the key.
  framework::Result Configure(const framework::ConfigSection& config, const DepthSettings& settings,
                              framework::Node& node);
  /// Starts the provider's timer (no-op for "none").
  void Activate(framework::Node& node, TruthFn truth);
  void Deactivate(framework::Node& node);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace iplan::perception
