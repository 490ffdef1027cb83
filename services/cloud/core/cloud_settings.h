// The keys of section `cloud` (config/cloud.yaml), declared once: read by
// the cloud service, listed by `iplan config defaults cloud`. The pipeline
// file (`pipeline`, iplan::cloud::CloudParams) is read with its own
// declaration (iplan/cloud/params.h).
#pragma once

#include <array>
#include <cmath>
#include <string>

#include "cloud_stage.h"  // beside this header
#include "iplan/cloud/camera.h"
#include "iplan/cloud/noise.h"
#include "iplan/core/name_value.h"

namespace iplan::cloud_service {

struct CloudSettings {
  std::string pipeline = "cloud_pipeline.yaml";
  std::string robot = "robots/panda.yaml";
  std::string frame_id = "world";
  cloud::CameraLookAt camera;
  cloud::DepthNoiseParams noise;
  std::array<double, 3> workspace_min = {-1.0, -1.0, -0.2};
  std::array<double, 3> workspace_max = {2.0, 1.0, 1.5};
  double human_voxel = 0.03;
  double joint_state_timeout = 0.2;
  /// s; the robot is filtered out over its poses from this long before the
  /// cloud's stamp to this long after it (each sphere grown by how far it
  /// moves then): the joint states' stamps against the camera's.
  double self_filter_time = 0.05;
  TrackerParams tracking;
  MotionParams motion;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(pipeline, "iplan::cloud parameter file (camera frame), relative to the configuration file"));
    a->Visit(IPLAN_NVP(robot, "robot model for the self-filter, relative to the configuration file; \"\" = no robot in view"));
    a->Visit(IPLAN_NVP(frame_id, "frame of the outputs (the cell's)"));
    a->Visit(IPLAN_NVP(camera, "pose of the camera's optical frame in the cell frame"));
    a->Visit(IPLAN_NVP(noise, "the camera's noise model (Nguyen et al. 2012), for the human points' covariance"));
    a->Visit(IPLAN_NVP(workspace_min, "m, W; points outside the box are removed"));
    a->Visit(IPLAN_NVP(workspace_max, "m, W; above workspace_min on every axis"));
    a->Visit(IPLAN_NVP(human_voxel, "m, grid the human points are reduced on (0: every point), >= 0"));
    a->Visit(IPLAN_NVP(joint_state_timeout, "s between a cloud's stamp and the joint state used to filter the robot out, > 0"));
    a->Visit(IPLAN_NVP(self_filter_time, "s; the robot is filtered out over its poses this long before and after a cloud's stamp, >= 0"));
    a->Visit(IPLAN_NVP(tracking, "the cluster tracker"));
    a->Visit(IPLAN_NVP(motion, "the human points' velocities: parts followed by constant-velocity Kalman filters"));
  }
  /// Empty when valid, else the reason.
  std::string Validate() const {
    if (std::string why = camera.Validate(); !why.empty()) return why;
    if (std::string why = noise.Validate(); !why.empty()) return "noise: " + why;
    for (int k = 0; k < 3; ++k) {
      if (!(workspace_min[k] < workspace_max[k])) return "workspace_min must be below workspace_max on every axis";
    }
    if (!(human_voxel >= 0 && std::isfinite(human_voxel))) return "human_voxel must be >= 0 m";
    if (!(joint_state_timeout > 0 && std::isfinite(joint_state_timeout))) return "joint_state_timeout must be > 0 s";
    if (!(self_filter_time >= 0 && self_filter_time < 1.0)) return "self_filter_time must be in [0, 1) s";
    if (std::string why = tracking.Validate(); !why.empty()) return "tracking: " + why;
    if (std::string why = motion.Validate(); !why.empty()) return "motion: " + why;
    return "";
  }
  /// The stage's parameters from these (the pipeline left as default: the
  /// caller loads the file). Valid settings only.
  CloudStageParams StageParams() const {
    CloudStageParams p;
    p.X_WS = camera.Pose();
    p.noise = noise;
    p.workspace_min = Eigen::Vector3d(workspace_min[0], workspace_min[1], workspace_min[2]);
    p.workspace_max = Eigen::Vector3d(workspace_max[0], workspace_max[1], workspace_max[2]);
    p.human_voxel = human_voxel;
    p.tracking = tracking;
    p.motion = motion;
    return p;
  }
};

}  // namespace iplan::cloud_service
