#include "iplan/viewer/web_dir.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "iplan/core/process.h"

namespace iplan::viewer {
namespace fs = std::filesystem;

std::string WebDir() {
  std::vector<std::string> candidates;
  if (const char* e = std::getenv("IPLAN_WEB_DIR"); e && *e) candidates.push_back(e);
  candidates.push_back(core::ExecutableDir() + "/../share/iplan/web");
  candidates.push_back(IPLAN_WEB_SOURCE_DIR);
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::exists(fs::path(c) / "dist" / "index.html", ec)) return fs::weakly_canonical(c, ec).string();
  }
  return "";
}

std::string NodeExecutable() {
  if (const char* e = std::getenv("IPLAN_NODE"); e && *e) return e;
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/usr/local/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    std::error_code ec;
    const fs::path p = fs::path(d) / "node";
    if (fs::exists(p, ec)) return p.string();
  }
  return "";
}

}  // namespace iplan::viewer
