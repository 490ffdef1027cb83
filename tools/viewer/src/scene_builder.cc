#include "iplan/viewer/scene_builder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <stdexcept>

#include "iplan/adapters/adapters.h"
#include "iplan/msg/time.h"

namespace iplan::viewer {
namespace {

using nlohmann::json;

json Color(const Rgba& c) { return {{"r", c.r}, {"g", c.g}, {"b", c.b}, {"a", c.a}}; }
json Point(const Eigen::Vector3d& p) { return {{"x", p.x()}, {"y", p.y()}, {"z", p.z()}}; }
json Pose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q = Eigen::Quaterniond::Identity()) {
  return {{"position", Point(p)}, {"orientation", {{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}}}};
}
json Stamp(const msg::Time& t) { return {{"sec", t.sec}, {"nsec", t.nanosec}}; }

json Sphere(const Eigen::Vector3d& c, double radius, const Rgba& color) {
  const double d = 2 * radius;
  return {{"pose", Pose(c)}, {"size", {{"x", d}, {"y", d}, {"z", d}}}, {"color", Color(color)}};
}

// A LINE_STRIP (type 0) or LINE_LIST (type 2) primitive in the entity frame.
json Line(int type, json points, double thickness, const Rgba& color) {
  return {{"type", type},
          {"pose", Pose(Eigen::Vector3d::Zero())},
          {"thickness", thickness},
          {"scale_invariant", false},
          {"points", std::move(points)},
          {"color", Color(color)},
          {"colors", json::array()},
          {"indices", json::array()}};
}

json Text(const Eigen::Vector3d& at, const std::string& text, const Rgba& color) {
  return {{"pose", Pose(at)}, {"billboard", true}, {"font_size", 14.0}, {"scale_invariant", true},
          {"color", Color(color)}, {"text", text}};
}

// An empty entity in the world frame; lifetime 0: kept until replaced.
json Entity(const std::string& id, const msg::Time& stamp) {
  json e = {{"timestamp", Stamp(stamp)}, {"frame_id", "world"}, {"id", id},
            {"lifetime", {{"sec", 0}, {"nsec", 0}}}, {"frame_locked", false}, {"metadata", json::array()}};
  for (const char* k : {"arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"}) {
    e[k] = json::array();
  }
  return e;
}

json Update(json entity) { return {{"deletions", json::array()}, {"entities", json::array({std::move(entity)})}}; }

const Rgba kRobot{1.0, 0.55, 0.1, 0.55};
const Rgba kRobotLink{0.25, 0.25, 0.25, 1.0};
const Rgba kGhost{1.0, 0.55, 0.1, 0.12};
const Rgba kPerson{0.2, 0.55, 1.0, 0.75};
const Rgba kBone{0.05, 0.2, 0.6, 1.0};
const Rgba kPath{0.0, 0.8, 0.3, 1.0};
const Rgba kOldPath{0.5, 0.5, 0.5, 0.6};
// One hue per predicted action rank (most probable first).
const Rgba kActionColors[] = {{0.85, 0.1, 0.6, 1}, {0.6, 0.2, 0.9, 1}, {0.1, 0.7, 0.8, 1}, {0.9, 0.8, 0.1, 1}};

}  // namespace

CellModel LoadCellModel(const std::string& robot_file, const std::string& scene_file, const std::string& body_file) {
  CellModel m;
  m.robot = collision::LoadRobotModel(robot_file);
  m.scene = collision::LoadSceneParams(scene_file);
  if (const std::string why = m.scene.Validate(); !why.empty()) throw std::runtime_error(scene_file + ": " + why);
  try {
    m.body = collision::HumanBodyModel(collision::LoadHumanBodyParams(body_file));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(body_file + ": " + e.what());
  }
  return m;
}

SceneBuilder::SceneBuilder(CellModel model, SceneBuilderOptions options)
    : model_(std::move(model)), options_(options), data_(model_.robot) {}

void SceneBuilder::Reject(const std::string& why) {
  ++rejected_;
  last_rejection_ = why;
}

json SceneBuilder::Static(const msg::Time& stamp) const {
  json e = Entity(entity::kStatic, stamp);
  for (const auto& o : model_.scene.objects) {
    const Eigen::Vector3d p = o.X_WO.translation();
    const Eigen::Quaterniond q(o.X_WO.rotation());
    const Rgba c = o.name == "table" ? Rgba{0.62, 0.5, 0.38, 1.0} : Rgba{0.6, 0.62, 0.66, 0.45};
    if (o.shape == collision::SceneObject::Shape::kBox) {
      e["cubes"].push_back({{"pose", Pose(p, q)}, {"size", Point(o.size)}, {"color", Color(c)}});
    } else {
      e["cylinders"].push_back({{"pose", Pose(p, q)},
                                {"size", {{"x", 2 * o.radius}, {"y", 2 * o.radius}, {"z", o.length}}},
                                {"bottom_scale", 1.0}, {"top_scale", 1.0}, {"color", Color(c)}});
    }
    e["metadata"].push_back({{"key", o.name}, {"value", o.shape == collision::SceneObject::Shape::kBox ? "box" : "cylinder"}});
  }
  return Update(std::move(e));
}

std::optional<Eigen::VectorXd> SceneBuilder::JointVector(const std::vector<std::string>& names,
                                                         const std::vector<double>& q) {
  const auto& r = model_.robot;
  Eigen::VectorXd v(r.nq);
  if (names.empty()) {  // positional
    if (static_cast<int>(q.size()) < r.nq) {
      Reject("joint state has " + std::to_string(q.size()) + " positions, the robot " + std::to_string(r.nq));
      return std::nullopt;
    }
    for (int i = 0; i < r.nq; ++i) v[i] = q[i];
    return v;
  }
  if (names.size() != q.size()) {
    Reject("joint state has " + std::to_string(names.size()) + " names and " + std::to_string(q.size()) + " positions");
    return std::nullopt;
  }
  for (int i = 0; i < r.nq; ++i) {
    const std::string& want = r.joints[r.q_joints[i]].name;
    auto it = std::find(names.begin(), names.end(), want);
    if (it == names.end()) {
      Reject("joint state lacks joint '" + want + "'");
      return std::nullopt;
    }
    v[i] = q[it - names.begin()];
  }
  return v;
}

Eigen::Vector3d SceneBuilder::EndEffector(const Eigen::VectorXd& q) {
  collision::CalcForwardKinematics(model_.robot, q, &data_);
  return data_.X_WL.back().translation();
}

namespace {

// In-place writers: once an array element exists, only its numbers change
// (no allocation), so a steady stream of updates costs little.
void SetXyz(json& q, const Eigen::Vector3d& p) {
  q["x"] = p.x();
  q["y"] = p.y();
  q["z"] = p.z();
}

void PutPoint(json& array, std::size_t i, const Eigen::Vector3d& p) {
  if (i >= array.size()) array.push_back(Point(p));
  else SetXyz(array[i], p);
}

void PutSphereAt(json& array, std::size_t i, const Eigen::Vector3d& c, double radius, const Rgba& color) {
  if (i >= array.size()) {
    array.push_back(Sphere(c, radius, color));
    return;
  }
  json& s = array[i];
  SetXyz(s["pose"]["position"], c);
  json& size = s["size"];
  size["x"] = size["y"] = size["z"] = 2 * radius;
  json& k = s["color"];
  k["r"] = color.r;
  k["g"] = color.g;
  k["b"] = color.b;
  k["a"] = color.a;
}

void Truncate(json& array, std::size_t n) {
  while (array.size() > n) array.erase(array.size() - 1);
}

}  // namespace

json& SceneBuilder::Persistent(const char* id, const msg::Time& stamp) {
  auto it = updates_.find(id);
  if (it == updates_.end()) it = updates_.emplace(id, Update(Entity(id, stamp))).first;
  json& e = it->second["entities"][0];
  e["timestamp"]["sec"] = stamp.sec;
  e["timestamp"]["nsec"] = stamp.nanosec;
  return e;
}

void SceneBuilder::PutRobotSpheres(json& array, std::size_t first, const Eigen::VectorXd& q, const Rgba& color) {
  collision::CalcForwardKinematics(model_.robot, q, &data_);
  for (std::size_t i = 0; i < model_.robot.spheres.size(); ++i) {
    PutSphereAt(array, first + i, data_.p_WS.col(static_cast<int>(i)), model_.robot.spheres[i].radius, color);
  }
}

const json* SceneBuilder::Robot(const msg::JointState& js) {
  const auto q = JointVector(js.name, js.position);
  if (!q) return nullptr;
  json& e = Persistent(entity::kRobot, js.header.stamp);
  PutRobotSpheres(e["spheres"], 0, *q, kRobot);
  // Links: a line from each link's parent link origin to its own origin.
  if (e["lines"].empty()) e["lines"].push_back(Line(2, json::array(), 0.02, kRobotLink));
  json& links = e["lines"][0]["points"];
  std::size_t n = 0;
  for (std::size_t l = 1; l < model_.robot.link_names.size(); ++l) {
    const int j = model_.robot.link_parent_joint[l];
    if (j < 0) continue;
    PutPoint(links, n++, data_.X_WL[model_.robot.joints[j].parent_link].translation());
    PutPoint(links, n++, data_.X_WL[l].translation());
  }
  if (e["metadata"].empty()) e["metadata"].push_back({{"key", "end_effector"}, {"value", model_.robot.link_names.back()}});
  return &updates_[entity::kRobot];
}

const json* SceneBuilder::Person(const msg::HumanSkeleton& s) {
  const auto& params = model_.body.params();
  Eigen::Matrix3Xd means(3, model_.body.num_joints());
  for (int j = 0; j < model_.body.num_joints(); ++j) {
    auto it = std::find_if(s.joints.begin(), s.joints.end(), [&](const auto& k) { return k.name == params.joints[j]; });
    if (it == s.joints.end()) {
      Reject("skeleton lacks joint '" + params.joints[j] + "'");
      return nullptr;
    }
    means.col(j) = Eigen::Vector3d(it->position.x, it->position.y, it->position.z);
  }
  json& e = Persistent(entity::kPerson, s.header.stamp);
  if (e["lines"].empty()) e["lines"].push_back(Line(2, json::array(), 0.015, kBone));
  json& bones = e["lines"][0]["points"];
  std::size_t n = 0;
  for (const auto& seg : params.segments) {
    PutPoint(bones, n++, means.col(std::find(params.joints.begin(), params.joints.end(), seg.joint_a) - params.joints.begin()));
    PutPoint(bones, n++, means.col(std::find(params.joints.begin(), params.joints.end(), seg.joint_b) - params.joints.begin()));
  }
  std::size_t i = 0;
  for (const auto& sp : model_.body.spheres()) {
    PutSphereAt(e["spheres"], i++, (1 - sp.u) * means.col(sp.joint_a) + sp.u * means.col(sp.joint_b), sp.radius, kPerson);
  }
  return &updates_[entity::kPerson];
}

const json* SceneBuilder::Prediction(const msg::HumanPrediction& p) {
  const auto& params = model_.body.params();
  const std::size_t nj = p.joint_names.size();
  std::vector<int> index(params.joints.size(), -1);
  for (std::size_t j = 0; j < params.joints.size(); ++j) {
    auto it = std::find(p.joint_names.begin(), p.joint_names.end(), params.joints[j]);
    if (it == p.joint_names.end()) {
      Reject("prediction lacks joint '" + params.joints[j] + "'");
      return nullptr;
    }
    index[j] = static_cast<int>(it - p.joint_names.begin());
  }
  for (const auto& a : p.actions) {
    if (a.joints.size() != nj * p.num_steps) {
      Reject("prediction of '" + a.action + "' has " + std::to_string(a.joints.size()) + " Gaussians, not steps x joints");
      return nullptr;
    }
  }
  std::vector<std::size_t> order(p.actions.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return p.actions[a].probability > p.actions[b].probability; });
  if (static_cast<int>(order.size()) > options_.prediction_actions) order.resize(options_.prediction_actions);
  json& e = Persistent(entity::kPrediction, p.header.stamp);
  const int steps = static_cast<int>(p.num_steps);
  const int drawn = std::min(options_.prediction_steps, steps);
  std::size_t n = 0;
  e["metadata"] = json::array();
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const auto& a = p.actions[order[rank]];
    Rgba c = kActionColors[rank % 4];
    c.a = 0.06 + 0.3 * std::clamp(a.probability, 0.0, 1.0);  // shaded by probability
    for (int k = 1; k <= drawn; ++k) {
      const int step = k * steps / drawn - 1;  // evenly spread, the last step included
      for (const auto& sp : model_.body.spheres()) {
        const auto& ga = a.joints[step * nj + index[sp.joint_a]].mean;
        const auto& gb = a.joints[step * nj + index[sp.joint_b]].mean;
        const Eigen::Vector3d c3 = (1 - sp.u) * Eigen::Vector3d(ga.x, ga.y, ga.z) + sp.u * Eigen::Vector3d(gb.x, gb.y, gb.z);
        PutSphereAt(e["spheres"], n++, c3, sp.radius, c);
      }
    }
    e["metadata"].push_back({{"key", a.action}, {"value", std::to_string(a.probability)}});
  }
  Truncate(e["spheres"], n);
  return &updates_[entity::kPrediction];
}

const json* SceneBuilder::Trajectory(const msg::JointTrajectory& t) {
  std::vector<Eigen::VectorXd> qs;
  for (const auto& pt : t.points) {
    const auto q = JointVector(t.joint_names, pt.positions);
    if (!q) return nullptr;
    qs.push_back(*q);
  }
  json& e = Persistent(entity::kTrajectory, t.header.stamp);
  json path = json::array();
  for (const auto& q : qs) path.push_back(Point(EndEffector(q)));
  e["lines"] = json::array();
  if (!previous_path_.empty()) e["lines"].push_back(Line(0, std::move(previous_path_), 0.006, kOldPath));
  e["lines"].push_back(Line(0, path, 0.012, kPath));
  const int n = static_cast<int>(qs.size());
  const std::size_t per_pose = model_.robot.spheres.size();
  std::size_t drawn = 0;
  for (int k = 1; k <= options_.ghost_poses && n > 0; ++k, ++drawn) {
    PutRobotSpheres(e["spheres"], drawn * per_pose, qs[k * (n - 1) / options_.ghost_poses], kGhost);
  }
  Truncate(e["spheres"], drawn * per_pose);
  e["metadata"] = json::array({{{"key", "waypoints"}, {"value", std::to_string(n)}}});
  previous_path_ = std::move(path);
  return &updates_[entity::kTrajectory];
}

namespace {

// Offset of FLOAT32 field `name`, or -1.
int FloatField(const msg::PointCloud2& c, const char* name) {
  for (const auto& f : c.fields) {
    if (f.name == name && f.datatype == msg::PointField::FLOAT32 && f.offset + 4 <= c.point_step) {
      return static_cast<int>(f.offset);
    }
  }
  return -1;
}

float ReadFloat(const uint8_t* p) {
  float v;
  std::memcpy(&v, p, sizeof v);  // little endian, as the host (checked by the caller)
  return v;
}

}  // namespace

const json* SceneBuilder::Obstacles(const msg::PointCloud2& c) {
  const int ox = FloatField(c, "x"), oy = FloatField(c, "y"), oz = FloatField(c, "z");
  const std::size_t n = static_cast<std::size_t>(c.width) * c.height;
  if (ox < 0 || oy < 0 || oz < 0) {
    Reject("obstacle cloud lacks FLOAT32 fields x, y, z");
    return nullptr;
  }
  if (c.is_bigendian || c.header.frame_id != "world" || c.data.size() < n * c.point_step) {
    Reject(c.is_bigendian ? "obstacle cloud is big endian" : c.header.frame_id != "world"
           ? "obstacle cloud in frame '" + c.header.frame_id + "', not the cell frame 'world'"
           : "obstacle cloud has fewer data bytes than width x height x point_step");
    return nullptr;
  }
  json& e = Persistent(entity::kObstacles, c.header.stamp);
  const std::size_t stride = std::max<std::size_t>(1, (n + options_.max_cloud_points - 1) / options_.max_cloud_points);
  const Rgba color{0.85, 0.25, 0.2, 1.0};
  json& cubes = e["cubes"];
  std::size_t drawn = 0;
  for (std::size_t i = 0; i < n; i += stride) {
    const uint8_t* p = c.data.data() + i * c.point_step;
    const Eigen::Vector3d v(ReadFloat(p + ox), ReadFloat(p + oy), ReadFloat(p + oz));
    if (!v.allFinite()) continue;
    if (drawn >= cubes.size()) {
      const double d = options_.cloud_point_size;
      cubes.push_back({{"pose", Pose(v)}, {"size", {{"x", d}, {"y", d}, {"z", d}}}, {"color", Color(color)}});
    } else {
      SetXyz(cubes[drawn]["pose"]["position"], v);
    }
    ++drawn;
  }
  Truncate(cubes, drawn);
  e["metadata"] = json::array({{{"key", "points"}, {"value", std::to_string(n)}}, {{"key", "drawn"}, {"value", std::to_string(drawn)}}});
  return &updates_[entity::kObstacles];
}

const json* SceneBuilder::Boxes(const msg::ObstacleArray& a) {
  if (a.header.frame_id != "world") {
    Reject("obstacles in frame '" + a.header.frame_id + "', not the cell frame 'world'");
    return nullptr;
  }
  json& e = Persistent(entity::kBoxes, a.header.stamp);
  const Rgba color{0.95, 0.45, 0.1, 0.45};
  json& cubes = e["cubes"];
  cubes = json::array();
  for (const cell::ObstacleBox& b : services::FromObstacles(a)) {
    // Oriented boxes in "world", half extents along their own axes.
    cubes.push_back({{"pose", Pose(b.centre, b.orientation)}, {"size", Point(2 * b.half_extents)}, {"color", Color(color)}});
  }
  e["metadata"] = json::array({{{"key", "boxes"}, {"value", std::to_string(a.obstacles.size())}}});
  return &updates_[entity::kBoxes];
}

const json* SceneBuilder::HumanPoints(const msg::HumanPoints& m) {
  if (m.header.frame_id != "world") {
    Reject("human points in frame '" + m.header.frame_id + "', not the cell frame 'world'");
    return nullptr;
  }
  const cell::HumanPoints p = services::FromHumanPoints(m);
  constexpr double kVelocityLead = 0.5;  // s drawn ahead along each part's velocity
  const Rgba tracked{0.55, 0.2, 0.85, 0.9}, untracked{0.9, 0.15, 0.15, 0.9}, arrow{0.35, 0.05, 0.6, 1.0};
  json& e = Persistent(entity::kHumanPoints, m.header.stamp);
  const std::size_t n = static_cast<std::size_t>(p.size());
  const std::size_t stride = std::max<std::size_t>(1, (n + options_.max_cloud_points - 1) / options_.max_cloud_points);
  const double d = p.voxel_size > 0 ? p.voxel_size : options_.cloud_point_size;
  json& cubes = e["cubes"];
  cubes = json::array();
  std::vector<Eigen::Vector3d> sum(p.motions.size(), Eigen::Vector3d::Zero());
  std::vector<int> count(p.motions.size(), 0);
  std::size_t n_tracked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d v = p.means.col(static_cast<Eigen::Index>(i));
    const int k = p.MotionIndexOf(static_cast<int>(i));  // in range: the boundary checked it
    const bool moving = k >= 0;
    if (moving) {
      sum[static_cast<std::size_t>(k)] += v;
      ++count[static_cast<std::size_t>(k)];
      ++n_tracked;
    }
    if (i % stride != 0) continue;
    cubes.push_back({{"pose", Pose(v)}, {"size", {{"x", d}, {"y", d}, {"z", d}}}, {"color", Color(moving ? tracked : untracked)}});
  }
  json segments = json::array();
  for (std::size_t k = 0; k < p.motions.size(); ++k) {
    if (count[k] == 0) continue;
    const Eigen::Vector3d c = sum[k] / count[k];
    segments.push_back(Point(c));
    segments.push_back(Point(c + kVelocityLead * p.motions[k].velocity));
  }
  e["lines"] = json::array();
  if (!segments.empty()) e["lines"].push_back(Line(2, std::move(segments), 0.01, arrow));
  e["metadata"] = json::array({{{"key", "points"}, {"value", std::to_string(n)}},
                               {{"key", "tracked"}, {"value", std::to_string(n_tracked)}},
                               {{"key", "motions"}, {"value", std::to_string(p.motions.size())}}});
  return &updates_[entity::kHumanPoints];
}

json SceneBuilder::Safety(const msg::CollisionRisk& r) const {
  static const char* kVerdicts[] = {"OK", "SLOW_DOWN", "PROTECTIVE_STOP"};
  static const Rgba kColors[] = {{0.1, 0.7, 0.2, 1}, {0.95, 0.6, 0.0, 1}, {0.9, 0.1, 0.1, 1}};
  const int v = std::min<int>(r.verdict, 2);
  char text[160];
  std::snprintf(text, sizeof text, "%s  separation %.2f m  S_p %.2f m  bound %.3f", kVerdicts[v], r.min_separation,
                r.protective_separation, r.max_bound);
  json e = Entity(entity::kSafety, r.header.stamp);
  e["texts"].push_back(Text({0.45, 0.0, 0.9}, text, kColors[v]));
  e["metadata"].push_back({{"key", "verdict"}, {"value", kVerdicts[v]}});
  return Update(std::move(e));
}

}  // namespace iplan::viewer
