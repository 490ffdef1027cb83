// CloudParams: validation and strict YAML loading.
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "iplan/cloud/pipeline.h"
#include "iplan/core/params.h"
#include "iplan/core/yaml.h"

namespace iplan::cloud {
namespace {

std::string Num(double v) { return core::ParamText(v); }

template <typename T>
T Read(const YAML::Node& node, const std::string& key, const std::string& path) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": key '" + key + "' has a value of the wrong type: '" +
                             YAML::Dump(node) + "'");
  }
}

Eigen::Vector3f ReadVector3(const YAML::Node& node, const std::string& key, const std::string& path) {
  const auto v = Read<std::vector<float>>(node, key, path);
  if (v.size() != 3)
    throw std::runtime_error(path + ": key '" + key + "' needs 3 numbers [x, y, z], got " +
                             std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

using Setter = std::function<void(CloudParams*, const YAML::Node&, const std::string& path)>;

template <typename T>
std::pair<const std::string, Setter> Field(const char* key, T CloudParams::*member) {
  return {key, [key, member](CloudParams* p, const YAML::Node& v, const std::string& path) {
            p->*member = Read<T>(v, key, path);
          }};
}

std::pair<const std::string, Setter> VectorField(const char* key, Eigen::Vector3f CloudParams::*member) {
  return {key, [key, member](CloudParams* p, const YAML::Node& v, const std::string& path) {
            p->*member = ReadVector3(v, key, path);
          }};
}

const std::map<std::string, Setter>& Setters() {
  static const std::map<std::string, Setter> setters = {
      VectorField("crop_min", &CloudParams::crop_min),
      VectorField("crop_max", &CloudParams::crop_max),
      Field("self_filter_margin", &CloudParams::self_filter_margin),
      Field("plane_sample_stride", &CloudParams::plane_sample_stride),
      Field("plane_max_iterations", &CloudParams::plane_max_iterations),
      Field("plane_fit_distance", &CloudParams::plane_fit_distance),
      Field("table_distance", &CloudParams::table_distance),
      Field("table_distance_per_m2", &CloudParams::table_distance_per_m2),
      Field("min_table_points", &CloudParams::min_table_points),
      Field("max_object_height", &CloudParams::max_object_height),
      Field("stride", &CloudParams::stride),
      Field("cluster_distance", &CloudParams::cluster_distance),
      Field("cluster_distance_per_m2", &CloudParams::cluster_distance_per_m2),
      Field("min_obstacle_points", &CloudParams::min_obstacle_points),
      Field("normal_window_px", &CloudParams::normal_window_px),
      Field("concave_margin", &CloudParams::concave_margin),
      Field("crease_offset_px", &CloudParams::crease_offset_px),
      Field("step_normal_deg", &CloudParams::step_normal_deg),
      Field("step_angle_deg", &CloudParams::step_angle_deg),
      Field("min_part_points", &CloudParams::min_part_points),
      Field("concave_region_share", &CloudParams::concave_region_share),
      Field("concave_region_depth_px", &CloudParams::concave_region_depth_px),
      Field("voxel_size", &CloudParams::voxel_size),
      Field("euclidean_tolerance", &CloudParams::euclidean_tolerance),
      Field("textbook_min_cluster", &CloudParams::textbook_min_cluster),
  };
  return setters;
}

}  // namespace

std::string CloudParams::Validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  auto nonneg = [](double v) { return std::isfinite(v) && v >= 0; };
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(crop_min[k]) || !std::isfinite(crop_max[k]) || !(crop_min[k] < crop_max[k]))
      return "crop_min must be below crop_max on every axis, got axis " + std::to_string(k) + ": " +
             Num(crop_min[k]) + " .. " + Num(crop_max[k]);
  if (!nonneg(self_filter_margin)) return "self_filter_margin must be >= 0, got " + Num(self_filter_margin);
  if (plane_sample_stride < 1) return "plane_sample_stride must be >= 1, got " + std::to_string(plane_sample_stride);
  if (plane_max_iterations < 1)
    return "plane_max_iterations must be >= 1, got " + std::to_string(plane_max_iterations);
  if (!positive(plane_fit_distance)) return "plane_fit_distance must be > 0, got " + Num(plane_fit_distance);
  if (!positive(table_distance)) return "table_distance must be > 0, got " + Num(table_distance);
  if (!nonneg(table_distance_per_m2))
    return "table_distance_per_m2 must be >= 0, got " + Num(table_distance_per_m2);
  if (min_table_points < 3) return "min_table_points must be >= 3, got " + std::to_string(min_table_points);
  if (!positive(max_object_height)) return "max_object_height must be > 0, got " + Num(max_object_height);
  if (stride < 1 || stride > 8) return "stride must be in 1..8, got " + std::to_string(stride);
  if (!positive(cluster_distance)) return "cluster_distance must be > 0, got " + Num(cluster_distance);
  if (!nonneg(cluster_distance_per_m2))
    return "cluster_distance_per_m2 must be >= 0, got " + Num(cluster_distance_per_m2);
  if (min_obstacle_points < 1)
    return "min_obstacle_points must be >= 1, got " + std::to_string(min_obstacle_points);
  if (normal_window_px < 1 || normal_window_px > 10)
    return "normal_window_px must be in 1..10, got " + std::to_string(normal_window_px);
  if (!(concave_margin >= 0)) return "concave_margin must be >= 0, got " + Num(concave_margin);
  if (crease_offset_px < 1 || crease_offset_px > 10)
    return "crease_offset_px must be in 1..10, got " + std::to_string(crease_offset_px);
  if (!(step_normal_deg >= 0 && step_normal_deg <= 90))
    return "step_normal_deg must be in 0..90, got " + Num(step_normal_deg);
  if (!(step_angle_deg >= 0 && step_angle_deg <= 90))
    return "step_angle_deg must be in 0..90, got " + Num(step_angle_deg);
  if (min_part_points < 1)
    return "min_part_points must be >= 1, got " + std::to_string(min_part_points);
  if (!(concave_region_share >= 0)) return "concave_region_share must be >= 0, got " + Num(concave_region_share);
  if (concave_region_depth_px < 1 || concave_region_depth_px > 20)
    return "concave_region_depth_px must be in 1..20, got " + std::to_string(concave_region_depth_px);
  if (!positive(voxel_size)) return "voxel_size must be > 0, got " + Num(voxel_size);
  if (!positive(euclidean_tolerance)) return "euclidean_tolerance must be > 0, got " + Num(euclidean_tolerance);
  if (textbook_min_cluster < 1)
    return "textbook_min_cluster must be >= 1, got " + std::to_string(textbook_min_cluster);
  return "";
}

CloudParams LoadCloudParams(const std::string& path) {
  YAML::Node root;
  try {
    root = core::LoadYamlFile(path);  // a key twice is an error
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read cloud params: " + e.what());
  }
  CloudParams p;
  if (!root || root.IsNull()) return p;
  if (!root.IsMap()) throw std::runtime_error(path + ": cloud params must be a map");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const auto it = Setters().find(key);
    if (it == Setters().end()) throw std::runtime_error(path + ": unknown key '" + key + "'");
    it->second(&p, kv.second, path);
  }
  if (const std::string why = p.Validate(); !why.empty()) throw std::runtime_error(path + ": " + why);
  return p;
}

std::vector<std::pair<std::string, CloudParams>> LoadCloudParamsGrid(const std::string& path,
                                                                     const CloudParams& base) {
  YAML::Node root;
  try {
    root = core::LoadYamlFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read the parameter grid: " + e.what());
  }
  if (!root || !root.IsMap() || root.size() == 0)
    throw std::runtime_error(path + ": the parameter grid must be a map of keys to lists of values");
  std::vector<std::pair<std::string, CloudParams>> grid = {{"", base}};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const auto it = Setters().find(key);
    if (it == Setters().end()) throw std::runtime_error(path + ": unknown key '" + key + "'");
    std::vector<YAML::Node> values;
    if (kv.second.IsSequence() && !kv.second.IsNull()) {
      // [x, y, z] of a vector key is one value, a list of those is a list.
      const bool vector_key = key == "crop_min" || key == "crop_max";
      if (vector_key && kv.second.size() > 0 && kv.second[0].IsScalar()) values.push_back(kv.second);
      else for (const auto& v : kv.second) values.push_back(v);
    } else {
      values.push_back(kv.second);
    }
    if (values.empty()) throw std::runtime_error(path + ": key '" + key + "' has no values");
    std::vector<std::pair<std::string, CloudParams>> next;
    for (const auto& [name, params] : grid)
      for (const YAML::Node& v : values) {
        CloudParams p = params;
        it->second(&p, v, path);
        YAML::Emitter text;
        text << YAML::Flow << v;
        next.emplace_back(name + (name.empty() ? "" : " ") + key + "=" + text.c_str(), p);
      }
    grid = std::move(next);
  }
  for (const auto& [name, p] : grid)
    if (const std::string why = p.Validate(); !why.empty()) throw std::runtime_error(path + ": " + name + ": " + why);
  return grid;
}

}  // namespace iplan::cloud
