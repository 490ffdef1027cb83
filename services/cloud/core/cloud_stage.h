// The cloud service's whole per-frame stage, without DDS: crop to the
// workspace (cell frame), robot self-filter from the current joint state
// and the robot's collision spheres, the obstacle pipeline of iplan::cloud
// (table plane, segmentation), cluster tracking over frames (static vs
// moving), and the outputs: static obstacles as boxes, and the human points
// reduced on a voxel grid, each with the depth camera's noise covariance.
//
// Frames: W the cell frame (`world`, z up), S the camera's optical frame;
// X_WS the camera's pose in W. Metres, m^2 for covariances, ns for stamps.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "services/cloud/core/cluster_tracker.h"
#include "iplan/cell/human_points.h"
#include "iplan/cell/obstacle_box.h"
#include "services/cloud/core/point_motion.h"
#include "iplan/cloud/cloud.h"
#include "iplan/cloud/noise.h"
#include "iplan/cloud/pipeline.h"
#include "iplan/collision/robot_model.h"

namespace iplan::cloud_service {

struct CloudStageParams {
  cloud::CloudParams pipeline;                                 ///< S frame, iplan::cloud
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();      ///< camera pose in W
  Eigen::Vector3d workspace_min{-1.0, -1.0, -0.2};             ///< m, W; points outside are removed
  Eigen::Vector3d workspace_max{2.0, 1.0, 1.5};                ///< m, W
  cloud::DepthNoiseParams noise;                               ///< the camera's noise model
  double human_voxel = 0.03;                                   ///< m, grid the human points are reduced on
  TrackerParams tracking;
  MotionParams motion;                                         ///< the human points' velocities

  /// Empty when valid, else the first problem.
  std::string Validate() const;
};

struct StageOutput {
  std::vector<cell::ObstacleBox> obstacles;  ///< the static tracks: boxes upright in W (z along W's z), id = track id
  /// The human points as Gaussians in W (the camera's noise at each), with
  /// the velocities of the tracked parts they belong to (point_motion.h);
  /// stamped with the cloud, voxel_size = human_voxel.
  cell::HumanPoints human;
  bool table_found = false;
  int table_points = 0;
  int clusters = 0;           ///< segments of this frame
  int cropped_points = 0;     ///< finite points outside the workspace
  bool self_filtered = false; ///< robot spheres were applied
};

class CloudStage {
 public:
  /// `robot` (may be null: no self-filter) is copied. Throws
  /// std::invalid_argument when params.Validate() fails.
  CloudStage(const CloudStageParams& params, const collision::RobotModel* robot);
  ~CloudStage();

  /// Joint names the self-filter expects, in q order (empty without a robot).
  std::vector<std::string> JointNames() const;

  /// Processes one cloud (S frame; points outside the workspace are set to
  /// NaN in place). `q` (model order, rad / m) places the robot's spheres;
  /// nullopt: no self-filter this frame, and then (with a robot) the frame
  /// does not update the tracking: every cluster is human, the known static
  /// obstacles are output unchanged. `around`: the robot's poses shortly
  /// before and after the stamp (same order as q); each sphere, placed at
  /// q, grows by the farthest it is from there in them, so that the robot
  /// is filtered out over its path while the joint states' timing against
  /// the camera's is uncertain. Never throws on cloud content.
  StageOutput Process(cloud::Cloud* cloud, const std::optional<Eigen::VectorXd>& q, int64_t stamp_ns,
                      const std::vector<Eigen::VectorXd>& around = {});

  /// Process's first step alone: sets the finite points outside the
  /// workspace (S frame in, bounds in W) to NaN in place and counts them in
  /// out->cropped_points.
  void Crop(cloud::Cloud* cloud, StageOutput* out) const;

 private:
  std::vector<cloud::Sphere> RobotSpheres(const Eigen::VectorXd& q, const std::vector<Eigen::VectorXd>& around);
  /// The human points, voxel-reduced, with noise covariances; `track`: their
  /// parts' motions are updated from them (else they are all not tracked).
  void HumanPoints(const cloud::Cloud& cloud, const std::vector<int>& indices, bool track, int64_t stamp_ns,
                   StageOutput* out);

  CloudStageParams params_;
  Eigen::Isometry3d X_SW_;
  std::unique_ptr<collision::RobotModel> robot_;
  std::unique_ptr<collision::RobotData> robot_data_;
  cloud::ObstaclePipeline pipeline_;
  ClusterTracker tracker_;
  MotionTracker motion_;
};

}  // namespace iplan::cloud_service
