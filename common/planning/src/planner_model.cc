#include "planner_model.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace iplan::planning::internal {

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::string VectorText(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s.precision(10);
  s << "[";
  for (int i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v[i];
  s << "]";
  return s.str();
}

// The robot-neutral names of a planner file made this robot's: "" for the
// end effector, "<base>" in allowed_collisions.
PlannerParams ResolveRobotLinks(PlannerParams params, const collision::RobotModel& robot) {
  if (params.end_effector_link.empty() && !robot.link_names.empty())
    params.end_effector_link = robot.tool_link.empty() ? robot.link_names.back() : robot.tool_link;
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const auto& [link, object] : params.allowed_collisions) {
    if (link != "<base>") {
      pairs.emplace_back(link, object);
      continue;
    }
    std::vector<int> with_spheres;
    for (const auto& s : robot.spheres) with_spheres.push_back(s.link);
    std::sort(with_spheres.begin(), with_spheres.end());
    with_spheres.erase(std::unique(with_spheres.begin(), with_spheres.end()), with_spheres.end());
    for (std::size_t i = 0; i < with_spheres.size() && i < 2; ++i)
      pairs.emplace_back(robot.link_names[with_spheres[i]], object);
  }
  params.allowed_collisions = std::move(pairs);
  return params;
}

PlannerModel::PlannerModel(collision::RobotModel robot_in, collision::SceneParams scene_in, PlannerParams params_in) {
  if (const std::string why = params_in.Validate(); !why.empty())
    throw std::invalid_argument("PlannerParams: " + why);
  if (const std::string why = scene_in.Validate(); !why.empty())
    throw std::invalid_argument("SceneParams: " + why);
  robot = std::move(robot_in);
  scene = std::move(scene_in);
  params = ResolveRobotLinks(std::move(params_in), robot);
  if (robot.nq < 1) throw std::invalid_argument("Planner: robot has no joints");
  chains = std::make_unique<KinematicChains>(robot);
  ee_link = robot.FindLink(params.end_effector_link);
  if (ee_link < 0)
    throw std::invalid_argument("Planner: unknown end_effector_link '" + params.end_effector_link + "'");
  ee_offset = Eigen::Vector3d(params.end_effector_offset[0], params.end_effector_offset[1],
                              params.end_effector_offset[2]);
  for (const auto& o : scene.objects) objects.push_back(MakeClearanceObject(o));
  for (const auto& s : robot.spheres) {
    radii.push_back(s.radius);
    links.push_back(s.link);
  }
  for (std::size_t s = 0; s < radii.size(); ++s) {
    auto g = std::find_if(link_groups.begin(), link_groups.end(),
                          [&](const std::vector<int>& v) { return links[v[0]] == links[s]; });
    if (g == link_groups.end())
      link_groups.push_back({static_cast<int>(s)});
    else
      g->push_back(static_cast<int>(s));
  }
  sphere_group.assign(radii.size(), 0);
  for (std::size_t g = 0; g < link_groups.size(); ++g)
    for (int s : link_groups[g]) sphere_group[s] = static_cast<int>(g);
  checked.assign(radii.size(), std::vector<char>(objects.size(), 1));
  for (const auto& [link_name, object_name] : params.allowed_collisions) {
    const int link = robot.FindLink(link_name);
    if (link < 0)
      throw std::invalid_argument("Planner: allowed_collisions names unknown link '" + link_name + "'");
    int object = -1;
    for (int o = 0; o < static_cast<int>(scene.objects.size()); ++o)
      if (scene.objects[o].name == object_name) object = o;
    if (object < 0) continue;  // scenes without this object: nothing to allow
    for (std::size_t s = 0; s < radii.size(); ++s)
      if (links[s] == link) checked[s][object] = 0;
  }
  const int nq = robot.nq;
  lower = robot.LowerLimits();
  upper = robot.UpperLimits();
  vmax.resize(nq);
  amax.resize(nq);
  for (int j = 0; j < nq; ++j) {
    const auto& L = robot.joints[robot.q_joints[j]].limits;
    if (!(L.velocity > 0.0) || !(L.acceleration > 0.0))
      throw std::invalid_argument("Planner: joint " + std::to_string(j) +
                                  " needs positive velocity and acceleration limits");
    vmax[j] = L.velocity;
    amax[j] = L.acceleration;
  }
}

double PlannerModel::LinkBall(const collision::RobotData& data, const std::vector<int>& group,
                              Eigen::Vector3d* c) const {
  c->setZero();
  for (int sp : group) *c += data.p_WS.col(sp);
  *c /= static_cast<double>(group.size());
  double cover = 0.0;
  for (int sp : group) cover = std::max(cover, (data.p_WS.col(sp) - *c).norm() + radii[sp]);
  return cover;
}

double PlannerModel::Clearance(const collision::RobotData& data, const std::vector<ClearanceObject>* obstacles) const {
  // Per link, a ball around its spheres first (the signed distance is
  // 1-Lipschitz; 1e-9 against rounding): links that cannot go below the
  // best so far are skipped. The minimum is the same.
  double best = std::numeric_limits<double>::infinity();
  const int ns = static_cast<int>(objects.size());
  const int no = ns + (obstacles ? static_cast<int>(obstacles->size()) : 0);
  for (const std::vector<int>& grp : link_groups) {
    Eigen::Vector3d c;
    const double cover = LinkBall(data, grp, &c);
    for (int o = 0; o < no; ++o) {
      if (!Checked(grp[0], o)) continue;  // allowed pairs are per link
      const auto& ob = o < ns ? objects[o] : (*obstacles)[o - ns];
      if ((c - ob.centre_W).norm() - ob.bounding_radius - cover >= best + 1e-9) continue;
      if (PointSignedDistance(ob, c, nullptr) - cover >= best + 1e-9) continue;
      for (int s : grp) {
        const Eigen::Vector3d p = data.p_WS.col(s);
        if ((p - ob.centre_W).norm() - ob.bounding_radius - radii[s] >= best) continue;
        best = std::min(best, PointSignedDistance(ob, p, nullptr) - radii[s]);
      }
    }
  }
  return best;
}

}  // namespace iplan::planning::internal

namespace iplan::planning {

PlannerParams AdaptLinksToRobot(PlannerParams params, const collision::RobotModel& robot) {
  if (robot.link_names.empty()) return params;
  if (robot.FindLink(params.end_effector_link) < 0) {
    params.end_effector_link = robot.tool_link.empty() ? robot.link_names.back() : robot.tool_link;
    params.end_effector_offset = {0.0, 0.0, 0.0};
  }
  bool all_known = true;
  for (const auto& [link, object] : params.allowed_collisions)
    all_known = all_known && (link == "<base>" || robot.FindLink(link) >= 0);
  if (all_known) return params;
  params.allowed_collisions = {{"<base>", "table"}};
  return internal::ResolveRobotLinks(params, robot);
}

}  // namespace iplan::planning
