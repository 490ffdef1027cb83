// The one-shot depth-camera pipeline: robot self-filter, crop to the
// workspace, table plane (RANSAC), segmentation of what stands on the table
// into obstacles. Two implementations behind one result type:
//   - ObstaclePipeline (ours): works on the organised image structure
//     (strided image, depth-discontinuity connected components); see
//     docs/perception-clouds.md for the method and its measured quality.
//   - TextbookPipeline: crop, voxel grid, RANSAC plane, Euclidean
//     clustering, kept as the reference the benchmark and the evaluation
//     compare against.
//
// Frame: everything here is in the sensor's optical frame S of the input
// cloud (x right, y down, z along the view), metres. A caller with the
// robot's spheres in the world frame W transforms them with X_SW first.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/cloud/cloud.h"

namespace iplan::cloud {

/// Per-point labels of a result (one per input point, file order).
constexpr int kLabelRemoved = 0;  ///< invalid, cropped, self-filtered, off-table or unclustered
constexpr int kLabelTable = 1;    ///< on the table plane
/// Obstacle with id k (k >= 1) is labelled k + 1.
constexpr int LabelOfObstacle(int id) { return id + 1; }

/// A sphere of the robot's collision model, sensor frame.
struct Sphere {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  ///< p_SC, metres
  float radius = 0;                                  ///< metres
};

/// The supporting table plane: normal . p + offset = 0 for p on the plane.
struct Table {
  bool found = false;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  ///< unit, pointing towards the sensor
  float offset = 0;                                  ///< metres
  int points = 0;                                    ///< input points labelled table
};

/// One segmented obstacle (a part of an object, as the creases cut it) and
/// the oriented box B around its points in S (FitOrientedBox: upright on
/// the table with the smallest footprint when a table was found, else
/// along the points' principal axes).
struct Obstacle {
  int id = 0;  ///< 1, 2, ... by decreasing size
  /// Obstacles of one group form one surface connected in depth (parts of
  /// one object cut at creases, or objects touching); 1, 2, ... in the
  /// order of their first obstacle.
  int group = 0;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();                 ///< p_SB, box centre, metres
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();  ///< R_SB (z_B along the table normal)
  Eigen::Vector3f half_extents = Eigen::Vector3f::Zero();           ///< along B's axes, metres, >= 0
  std::vector<int> indices;                                         ///< input point indices, ascending
};

struct Result {
  Table table;
  std::vector<Obstacle> obstacles;
  std::vector<int> labels;  ///< one per input point: kLabelTable, LabelOfObstacle(id) or kLabelRemoved
};

/// Parameters (defaults suit a Kinect-class camera 0.5-2 m from a table).
struct CloudParams {
  // Workspace box in S; points outside are removed.
  Eigen::Vector3f crop_min{-1.5f, -1.5f, 0.3f};  ///< metres
  Eigen::Vector3f crop_max{1.5f, 1.5f, 2.5f};    ///< metres
  float self_filter_margin = 0.02f;  ///< metres added to every robot sphere's radius

  // Table plane.
  int plane_sample_stride = 4;         ///< pixel stride of the points RANSAC sees
  int plane_max_iterations = 200;      ///< RANSAC iterations
  float plane_fit_distance = 0.01f;    ///< metres, RANSAC inlier distance
  /// A kept point within table_distance + table_distance_per_m2 *
  /// max(0, z^2 - 1 m^2) (metres, z its depth) of the plane is table: depth
  /// noise grows as z^2.
  float table_distance = 0.007f;
  float table_distance_per_m2 = 0.004f;
  int min_table_points = 5000;         ///< fewer input points on the plane: no table
  float max_object_height = 1.2f;      ///< metres above the table (a person reaching over it); higher points are removed

  // Segmentation (ours).
  int stride = 2;                      ///< pixel stride of the segmentation image (1 = full)
  float cluster_distance = 0.015f;     ///< metres between neighbouring pixels at 1 m depth
  float cluster_distance_per_m2 = 0.0f;  ///< metres per m^2 of depth added
  int min_obstacle_points = 400;       ///< input points; smaller segments are removed
  /// Normals: PCA of the candidates within normal_window_px strided
  /// pixels (a (2m+1)^2 window) reachable without a depth gap.
  int normal_window_px = 4;
  /// Creases split segments into parts: a pixel is on a crease when the
  /// pixels crease_offset_px (strided) to either side of it, along a row or
  /// a column, have normals meeting concavely, d . (n_b - n_a) <
  /// -concave_margin (d the unit vector from a to b; >= 2 switches it off),
  /// or normals within step_normal_deg (degrees) of each other while d
  /// leaves their mean tangent plane by more than step_angle_deg (a step
  /// between parallel faces: a box on a flat one, its side seen at a
  /// grazing angle; >= 90 switches it off).
  float concave_margin = 0.1f;
  int crease_offset_px = 2;
  float step_normal_deg = 20.0f;
  float step_angle_deg = 30.0f;
  /// Connected crease pixels and connected other pixels form fragments; a
  /// segment is split into its fragments of at least min_part_points input
  /// points (smaller ones join the part they border most). A crease
  /// fragment counts only when at least concave_region_share *
  /// min_part_points of it lie deeper than concave_region_depth_px
  /// (strided, chessboard distance to the nearest non-crease pixel) inside
  /// it and it borders at most one non-crease fragment of min_part_points:
  /// a concave surface (the inside of a bowl, bordering its outside), not a
  /// band along a crease between two surfaces; concave_region_share > 1
  /// switches concave parts off.
  int min_part_points = 800;
  float concave_region_share = 0.1f;
  int concave_region_depth_px = 3;

  // Textbook pipeline.
  float voxel_size = 0.01f;            ///< metres
  float euclidean_tolerance = 0.02f;   ///< metres
  int textbook_min_cluster = 50;       ///< voxels

  /// Empty when valid, else the first problem ("stride must be >= 1").
  std::string Validate() const;
};

/// Loads CloudParams from a YAML file strictly: any key not in CloudParams
/// (names as in the struct, vectors as [x, y, z]), a wrong type or a failed
/// Validate() throws std::runtime_error "<path>: <what>" naming the key.
/// Keys left out keep their defaults; an empty file gives the defaults.
CloudParams LoadCloudParams(const std::string& path);

/// A grid of parameter settings for cross-validation: a YAML map of
/// CloudParams keys to lists of values (a single value is a list of one),
/// e.g. `{min_part_points: [400, 800], concave_margin: [0.05, 0.1]}`.
/// Returns every combination applied to `base`, in the file's order (the
/// last key varying fastest), each with its name "key=value key=value".
/// Throws std::runtime_error "<path>: ..." for an unknown key, a wrong type,
/// an empty list or a combination that fails Validate().
std::vector<std::pair<std::string, CloudParams>> LoadCloudParamsGrid(const std::string& path,
                                                                     const CloudParams& base);

/// Our pipeline. Holds its work buffers, so a second call on a cloud of the
/// same size does not grow them. Not thread-safe (one per thread).
class ObstaclePipeline {
 public:
  /// Throws std::invalid_argument when params.Validate() fails.
  explicit ObstaclePipeline(const CloudParams& params);
  ~ObstaclePipeline();
  ObstaclePipeline(const ObstaclePipeline&) = delete;
  ObstaclePipeline& operator=(const ObstaclePipeline&) = delete;

  /// Processes one cloud. `robot_spheres` (S frame) remove the robot's own
  /// points. An unorganised cloud is processed as one row (no image
  /// neighbours: use TextbookPipeline for those). Never throws on cloud
  /// content (NaN, empty); throws std::invalid_argument when
  /// width * height != points.size().
  Result Process(const Cloud& cloud, const std::vector<Sphere>& robot_spheres = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The textbook PCL pipeline on the same parameters (crop, self-filter,
/// voxel grid, RANSAC plane on the voxels, Euclidean clustering); each input
/// point takes the label of its voxel. Thread-safe (no shared state).
Result TextbookPipeline(const Cloud& cloud, const CloudParams& params,
                        const std::vector<Sphere>& robot_spheres = {});

}  // namespace iplan::cloud
