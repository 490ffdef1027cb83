#include "robot_spheres_cli.h"

#include <algorithm>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include "iplan/collision/robot_model.h"
#include "iplan/collision/self_collision.h"
#include "iplan/core/atomic_file.h"

namespace iplan::collision {
namespace {

using nlohmann::json;

struct LinkRow {
  std::string link;
  std::vector<std::string> shapes;
  std::vector<std::string> mesh_files;
  int spheres = 0;
  int uncovered = 0;
  double max_excess = 0.0;
  double sampled_excess = 0.0;  // meshes: seen; primitives: their bound
  bool from_cache = true;
};

std::vector<LinkRow> Rows(const RobotModel& robot) {
  std::map<std::string, LinkRow> by_link;
  for (const ShapeCoverEntry& e : robot.cover_report) {
    LinkRow& row = by_link[e.link];
    row.link = e.link;
    row.shapes.push_back(e.cover.shape);
    row.max_excess = std::max(row.max_excess, e.cover.max_excess);
    row.sampled_excess = std::max(row.sampled_excess, e.mesh ? e.mesh->sampled_excess_m : e.cover.max_excess);
    if (e.mesh) {
      row.mesh_files.push_back(e.mesh_file);
      row.uncovered += e.mesh->uncovered_vertices;
      row.from_cache = row.from_cache && e.mesh->from_cache;
    }
  }
  for (const CollisionSphere& s : robot.spheres) ++by_link[robot.link_names[s.link]].spheres;
  std::vector<LinkRow> rows;
  // In the model's link order (parents first).
  for (const std::string& name : robot.link_names) {
    auto it = by_link.find(name);
    if (it == by_link.end() || it->second.shapes.empty()) continue;
    if (it->second.mesh_files.empty()) it->second.from_cache = false;
    rows.push_back(it->second);
  }
  return rows;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

json CoverFile(const RobotModel& robot) {
  json spheres = json::array();
  for (const CollisionSphere& s : robot.spheres) {
    spheres.push_back({{"link", robot.link_names[s.link]},
                       {"centre", {s.p_LS.x(), s.p_LS.y(), s.p_LS.z()}},
                       {"radius", s.radius}});
  }
  return {{"robot", robot.name}, {"spheres", spheres}};
}

// The self-collision link pairs: checked, and skipped with their reason.
json SelfCollisionJson(const RobotModel& robot, const SelfCollisionModel& self) {
  json checked = json::array(), skipped = json::array();
  for (const auto& [a, b] : self.checked) checked.push_back({robot.link_names[a], robot.link_names[b]});
  for (const LinkPair& p : self.skipped)
    skipped.push_back({{"links", {robot.link_names[p.link_a], robot.link_names[p.link_b]}},
                       {"reason", ToString(p.reason)},
                       {"min_distance_m", p.min_distance}});
  const SelfCollisionParams params;
  return {{"samples", params.samples}, {"checked", checked}, {"skipped", skipped}};
}

void PrintSelfCollision(const RobotModel& robot, const SelfCollisionModel& self, std::ostream& out) {
  int count[3] = {0, 0, 0};
  for (const LinkPair& p : self.skipped) ++count[static_cast<int>(p.reason)];
  out << "self-collision: " << self.checked.size() << " link pairs checked; skipped " << count[0] << " adjacent, "
      << count[1] << " always touching, " << count[2] << " never within "
      << SelfCollisionParams{}.never_margin << " m in " << SelfCollisionParams{}.samples << " samples\n";
  for (const auto& [a, b] : self.checked) out << "  checked " << robot.link_names[a] << " / " << robot.link_names[b] << "\n";
}

void PrintTable(const RobotModel& robot, const std::vector<LinkRow>& rows, double median, int total_uncovered,
                std::ostream& out) {
  out << "robot " << robot.name << ": " << robot.spheres.size() << " spheres on " << rows.size() << " links, "
      << robot.nq << " joints\n";
  out << std::left << std::setw(22) << "link" << std::setw(10) << "shapes" << std::right << std::setw(8) << "spheres"
      << std::setw(20) << "uncovered_vertices" << std::setw(14) << "max_excess_m" << std::setw(18)
      << "sampled_excess_m" << "  cover\n";
  for (const LinkRow& r : rows) {
    std::set<std::string> kinds(r.shapes.begin(), r.shapes.end());
    std::string shapes;
    for (const std::string& k : kinds) shapes += (shapes.empty() ? "" : ",") + k;
    out << std::left << std::setw(22) << r.link << std::setw(10) << shapes << std::right << std::setw(8) << r.spheres
        << std::setw(20) << r.uncovered << std::setw(14) << std::fixed << std::setprecision(4) << r.max_excess
        << std::setw(18) << r.sampled_excess << "  " << (r.mesh_files.empty() ? "primitive" : r.from_cache ? "cached" : "computed") << "\n";
  }
  out << "median max_excess_m " << std::fixed << std::setprecision(4) << median << ", uncovered vertices "
      << total_uncovered << "\n";
}

}  // namespace

int RunRobotSpheres(const RobotSpheresOptions& options, std::ostream& out, std::ostream& err) {
  try {
    RobotModelOptions model_options;
    if (options.no_cache) model_options.mesh_cache_dir = "";
    if (options.max_excess) {
      model_options.mesh_cover.max_excess = *options.max_excess;
      // Keep the split and the grid within what the excess allows.
      model_options.mesh_cover.max_edge = std::min(model_options.mesh_cover.max_edge, 1.5 * *options.max_excess);
      model_options.mesh_cover.grid_step = std::min(model_options.mesh_cover.grid_step, *options.max_excess);
    }
    const RobotModel robot = LoadRobotModel(options.robot, model_options);
    const std::vector<LinkRow> rows = Rows(robot);
    std::vector<double> excess;
    int total_uncovered = 0;
    double worst = 0.0;
    for (const LinkRow& r : rows) {
      excess.push_back(r.max_excess);
      total_uncovered += r.uncovered;
      worst = std::max(worst, r.max_excess);
    }
    const double median = Median(excess);
    const SelfCollisionModel self = ComputeSelfCollision(robot);
    if (!options.out.empty()) core::WriteFileAtomically(options.out, CoverFile(robot).dump(1) + "\n");
    if (options.json) {
      json links = json::array();
      for (const LinkRow& r : rows) {
        links.push_back({{"link", r.link},
                         {"shapes", r.shapes},
                         {"spheres", r.spheres},
                         {"uncovered_vertices", r.uncovered},
                         {"max_excess_m", r.max_excess},
                         {"sampled_excess_m", r.sampled_excess},
                         {"mesh_files", r.mesh_files},
                         {"from_cache", r.from_cache}});
      }
      out << json{{"robot", robot.name},
                  {"file", options.robot},
                  {"total_spheres", robot.spheres.size()},
                  {"median_max_excess_m", median},
                  {"max_max_excess_m", worst},
                  {"uncovered_vertices", total_uncovered},
                  {"links", links},
                  {"self_collision", SelfCollisionJson(robot, self)}}
                 .dump()
          << "\n";
    } else {
      PrintTable(robot, rows, median, total_uncovered, out);
      PrintSelfCollision(robot, self, out);
    }
    return total_uncovered == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    err << "iplan robot spheres: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace iplan::collision
