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
#include <vector>

#include <Eigen/Core>

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

/// One segmented obstacle: an axis-aligned box in S around its points.
struct Obstacle {
  int id = 0;                                              ///< 1, 2, ... by decreasing size
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();        ///< box centre, metres
  Eigen::Vector3f half_extents = Eigen::Vector3f::Zero();  ///< metres, >= 0
  std::vector<int> indices;                                ///< input point indices, ascending
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
  /// Concave creases split segments: a pixel whose neighbours
  /// crease_offset_px to either side (strided pixels, along a row or a
  /// column) have normals meeting with d . (n_b - n_a) < -concave_margin
  /// (d the unit vector between them) is a crease; >= 2 switches it off.
  float concave_margin = 0.1f;
  int crease_offset_px = 2;
  float normal_smoothing_px = 5.0f;  ///< normal window, strided pixels
  /// A segment is split along concave creases only into parts of at least
  /// this many input points (smaller parts join the neighbour they border
  /// most).
  int min_part_points = 800;
  /// Parts of one segment are merged back (faces of one object)
  /// when coplanar: normals within flat_angle_deg (degrees) and each
  /// centroid within coplanar_distance (metres) of the other's plane; or
  /// when they meet convexly: d . (n_a - n_b) > convex_margin (d the unit
  /// vector between their centroids, n their normals).
  float flat_angle_deg = 20.0f;
  float coplanar_distance = 0.01f;
  float convex_margin = 0.1f;

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
