#include "iplan/framework/service_file.h"

#include <filesystem>

namespace iplan::framework {

std::string CellFile(const std::string& dir, const std::string& name) {
  return (std::filesystem::path(dir) / (name + ".yaml")).string();
}

ServiceFile::ServiceFile(const std::string& path, const core::Overrides& overrides)
    : file_(path.empty() ? ConfigSection::FromString("{}", "(no configuration file)") : ConfigSection::Load(path)) {
  for (const auto& [key, yaml] : overrides) file_.Override(key, yaml);
  core::ReadParams(file_.Section("node"), &node_);  // every range: NodeOptions::Validate
}

}  // namespace iplan::framework
