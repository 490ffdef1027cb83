// One loader for a service's configuration file, used by the services
// themselves (RunService) and by every tool that needs a service's settings
// (`iplan demo`, `iplan eval`, `iplan cell-check`, the viewer, benchmarks),
// so a file means the same to all of them:
//
//   framework::ServiceFile f(framework::CellFile(dir, "perception"));
//   perception::PerceptionSettings p;
//   f.ReadSection("perception", &p).Finish();   // throws ConfigError listing every problem
//
// The file's `node` section (NodeSettings) is read on loading; each section
// is read into a struct declared with Serialize (iplan/core/params.h), its
// ranges checked by its Validate(). Finish() reports unknown keys, wrong
// types and failed ranges, each naming the file and the key, as the service
// does before it starts.
#pragma once

#include <string>

#include "iplan/core/params.h"
#include "iplan/framework/config.h"
#include "iplan/framework/node.h"

namespace iplan::framework {

/// `dir`/`name`.yaml: a service's file in a cell's configuration folder.
std::string CellFile(const std::string& dir, const std::string& name);

class ServiceFile {
 public:
  /// Loads `path` (empty: no file, every key at its default), applies the
  /// --set overrides, reads `node`. Throws ConfigError for a file that
  /// cannot be read or an override that cannot be applied.
  explicit ServiceFile(const std::string& path, const core::Overrides& overrides = {});

  /// Reads section `section` into `*settings` (problems recorded, reported
  /// by Finish). Returns *this, so reads chain.
  template <class S>
  ServiceFile& ReadSection(const std::string& section, S* settings) {
    core::ReadParams(file_.Section(section), settings);
    return *this;
  }
  /// The section itself, for a service's own reader (OnConfigure).
  ConfigSection Section(const std::string& section) { return file_.Section(section); }

  /// Throws ConfigError listing every problem, unknown keys included.
  void Finish() const { file_.Finish(); }

  const NodeSettings& node() const { return node_; }
  const std::string& path() const { return file_.file(); }
  /// `p` relative to the file's folder (absolute paths unchanged).
  std::string ResolvePath(const std::string& p) const { return file_.ResolvePath(p); }
  ConfigSection& file() { return file_; }

 private:
  ConfigSection file_;
  NodeSettings node_;
};

}  // namespace iplan::framework
