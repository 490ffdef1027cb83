// LoadRobotModel: the robot a config names, whatever form its file has
// (robot_model.h).
#include <cctype>
#include <fstream>
#include <stdexcept>

#include "iplan/collision/robot_model.h"
#include "iplan/core/params.h"

namespace iplan::collision {
namespace {

bool LooksLikeUrdf(const std::string& path) {
  auto ends = [&](const char* ext) {
    const std::string e(ext);
    if (path.size() < e.size()) return false;
    for (std::size_t i = 0; i < e.size(); ++i) {
      if (std::tolower(static_cast<unsigned char>(path[path.size() - e.size() + i])) != e[i]) return false;
    }
    return true;
  };
  if (ends(".urdf")) return true;
  std::ifstream f(path);
  char c = 0;
  while (f.get(c) && std::isspace(static_cast<unsigned char>(c))) {
  }
  return f && c == '<';
}

}  // namespace

RobotModel LoadRobotModel(const std::string& path, const RobotModelOptions& options) {
  if (!std::ifstream(path)) throw std::runtime_error(path + ": cannot open the robot file");
  if (LooksLikeUrdf(path)) return LoadRobotModelFromUrdf(path, options);
  const core::ConfigSection top = core::ConfigSection::Load(path);
  if (!top.Has("urdf")) return LoadRobotModelFromYaml(path, options);
  const UrdfOverlay o = core::LoadParamsFile<UrdfOverlay>(path, {}, core::ConfigSection::EmptyFile::kError);
  RobotModelOptions with = options;
  with.default_acceleration = o.acceleration;
  with.default_jerk = o.jerk;
  for (const auto& l : o.locked_joints) with.locked_joints[l.name] = l.value;
  const std::string urdf = top.ResolvePath(o.urdf);
  RobotModel model;
  try {
    model = LoadRobotModelFromUrdf(urdf, with);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + " (named by " + path + ")");
  }
  if (!o.tool_link.empty() && model.FindLink(o.tool_link) < 0) {
    throw std::runtime_error(path + ": key 'tool_link': " + urdf + " has no link '" + o.tool_link + "'");
  }
  model.tool_link = o.tool_link;
  return model;
}

}  // namespace iplan::collision
