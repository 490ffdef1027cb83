// What `iplan eval interaction` (cmd_eval.cc) and `iplan eval cell`
// (cmd_eval_cell.cc) share: the predictor list, number formatting, the
// spread in JSON, and loading the cell with its intent model (trained or
// cached as `iplan demo --prepare-only` does). Header only (the tool's
// sources are its cmd_*.cc and dds_*.cc files).
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/cell_sim/cell_config.h"
#include "tools/cell_sim/core/interaction_benchmark.h"
#include "dds_cell_model.h"
#include "fixed_text.h"
#include "iplan/framework/service.h"
#include "iplan/intent/model_io.h"

namespace iplan::cli::eval_common {

using Json = nlohmann::ordered_json;

inline const char* kAllPredictors = "none,constant-position,constant-velocity,model,oracle";

inline std::string SpreadText(const cell_sim::Spread& s, int digits) {
  return Fixed(s.median, digits) + " [" + Fixed(s.p10, digits) + ", " + Fixed(s.p90, digits) + "]";
}

inline Json SpreadJson(const cell_sim::Spread& s) { return Json{{"median", s.median}, {"p10", s.p10}, {"p90", s.p90}}; }

/// A ratio for JSON: infinity and NaN have no JSON number (null).
inline Json RatioJson(double r) { return std::isfinite(r) ? Json(r) : Json(nullptr); }

/// --predictors as a list; prints why (prefixed by `command`) and returns
/// nullopt when it is bad.
inline std::optional<std::vector<cell_sim::Predictor>> ParsePredictors(const std::string& text,
                                                                      const std::string& command) {
  std::vector<cell_sim::Predictor> predictors;
  std::stringstream ss(text);
  std::string name;
  while (std::getline(ss, name, ',')) {
    if (name.empty()) continue;
    const auto p = cell_sim::ParsePredictor(name);
    if (!p) {
      std::string known;
      for (const auto& n : cell_sim::PredictorNames()) known += (known.empty() ? "" : ", ") + n;
      std::cerr << command << ": unknown predictor '" << name << "' (known: " << known << ")\n";
      return std::nullopt;
    }
    if (std::find(predictors.begin(), predictors.end(), *p) != predictors.end()) {
      std::cerr << command << ": predictor '" << name << "' named twice\n";
      return std::nullopt;
    }
    predictors.push_back(*p);
  }
  if (predictors.empty()) {
    std::cerr << command << ": --predictors names no predictor\n";
    return std::nullopt;
  }
  return predictors;
}

/// The cell and its intent model, as both benchmarks load them.
struct CellInputs {
  std::string dir;  ///< the configuration folder
  cell_sim::CellConfig cell;
  CellModelResult model;
  std::shared_ptr<const intent::IntentModel> intent_model;
};

/// The configuration folder: `given`, else the default one. Throws
/// std::runtime_error when there is none.
inline std::string ConfigDir(const std::string& given) {
  const std::string dir = given.empty() ? framework::DefaultConfigDir() : given;
  if (dir.empty()) throw std::runtime_error("no configuration found (set --config-dir or $IPLAN_CONFIG_DIR)");
  return dir;
}

/// Loads the configuration folder `dir` (ConfigDir) for another arm `robot`
/// (empty: the configured) into in->cell, printing the goal notes. Throws
/// std::runtime_error.
inline void ReadConfiguration(const std::string& dir, const std::string& robot, int threads, CellInputs* in) {
  in->dir = dir;
  in->cell = cell_sim::LoadCellConfig(dir, threads, robot.empty() ? "" : std::filesystem::absolute(robot).string());
  for (const std::string& note : in->cell.goal_notes) std::cout << note << "\n";
}

/// Loads the intent model of in->dir's cell, trained or cached as `iplan
/// demo --prepare-only` does (in `model_dir` when config/models is not
/// writable; empty: a temporary folder). Throws std::runtime_error.
inline void PrepareIntentModel(const std::string& model_dir, bool retrain, CellInputs* in) {
  namespace fs = std::filesystem;
  const std::string fallback = model_dir.empty() ? (fs::temp_directory_path() / "iplan-eval-model").string() : model_dir;
  in->model = EnsureCellModel((fs::path(in->dir) / "perception.yaml").string(), (fs::path(in->dir) / "intent.yaml").string(),
                              fallback, retrain);
  in->intent_model = std::make_shared<const intent::IntentModel>(intent::LoadIntentModel(in->model.path));
}

/// Both: the configuration, then the intent model.
inline void LoadCell(const std::string& dir, const std::string& robot, int threads, const std::string& model_dir,
                     bool retrain, CellInputs* in) {
  ReadConfiguration(dir, robot, threads, in);
  PrepareIntentModel(model_dir, retrain, in);
}

}  // namespace iplan::cli::eval_common
