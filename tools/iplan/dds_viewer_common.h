// What `iplan view`, `iplan record` and `iplan demo --record` share: the
// cell model the scene is drawn from (the files the trajectory optimiser's
// configuration names), and starting/stopping a recorder next to a cell.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "iplan/core/process.h"
#include "iplan/viewer/scene_builder.h"

namespace iplan::cli {

/// The robot, scene and body files named by <config_dir>/trajopt.yaml
/// (trajopt.robot, trajopt.scene, trajopt.human_body); an explicit file
/// replaces each. @throws std::runtime_error naming the file and key.
viewer::CellModel LoadViewerCellModel(const std::string& config_dir, const std::string& robot = "",
                                      const std::string& scene = "", const std::string& body = "");

/// Starts `iplan record` (this executable) on `domain` writing `out` and
/// its per-topic counts to `out`.stats.json, with `env` added to its
/// environment (e.g. IPLAN_SECURITY); waits until it listens.
/// @throws std::runtime_error when it does not start.
std::unique_ptr<core::Process> StartRecorder(const std::string& vendor, int domain, const std::string& out,
                                             const std::string& config_dir, const std::string& log_base,
                                             const std::map<std::string, std::string>& env = {});

/// Stops a recorder (SIGTERM) and waits until the file is complete. Returns
/// an error text, or nullopt.
std::optional<std::string> StopRecorder(core::Process& recorder);

/// Writes the HTML report of a run (`iplan report`, this executable) to
/// `out`; returns an error text, or nullopt.
std::optional<std::string> WriteReport(const std::string& summary, const std::string& recording, const std::string& out);

}  // namespace iplan::cli
