// `iplan cloud obstacles`: the one-shot depth-camera pipeline on a recorded
// PCD file (table plane and obstacles, sensor frame, metres), and
// `iplan cloud eval`: both pipelines scored against the per-point ground
// truth of annotated scans (docs/perception-clouds.md).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command_registry.h"
#include "iplan/cloud/cloud.h"
#include "iplan/cloud/evaluate.h"
#include "iplan/cloud/pipeline.h"
#include "iplan/core/atomic_file.h"

namespace {

using iplan::cloud::CloudParams;
using iplan::cloud::Result;

struct ObstaclesOptions {
  std::string pcd, config, labels_out;
  bool json = false;
};

struct EvalOptions {
  std::string dir, config, cv;
  std::vector<std::string> cv_folds;  // each "sceneA sceneB ..." (file stems)
};

// ordered_json: the keys in the documented order.
using Json = nlohmann::ordered_json;

Json Vec(const Eigen::Vector3f& v) { return Json::array({v.x(), v.y(), v.z()}); }
// [x, y, z, w], as geometry_msgs/Quaternion orders them.
Json Quat(const Eigen::Quaternionf& q) { return Json::array({q.x(), q.y(), q.z(), q.w()}); }

std::string ResultJson(const Result& r, double seconds) {
  Json j;
  j["table"] = {{"normal", Vec(r.table.normal)}, {"offset", r.table.offset}, {"points", r.table.points}};
  j["obstacles"] = Json::array();
  for (const auto& o : r.obstacles)
    j["obstacles"].push_back({{"id", o.id},
                              {"centre", Vec(o.centre)},
                              {"half_extents", Vec(o.half_extents)},
                              {"points", o.indices.size()},
                              {"orientation", Quat(o.orientation)},
                              {"group", o.group}});
  j["time_s"] = seconds;
  return j.dump();
}

void PrintText(const Result& r, double seconds) {
  if (r.table.found)
    std::printf("table: normal [%.4f %.4f %.4f] offset %.4f m, %d points\n", r.table.normal.x(),
                r.table.normal.y(), r.table.normal.z(), r.table.offset, r.table.points);
  else
    std::printf("table: none found\n");
  std::printf("%zu obstacles (sensor frame, m):\n", r.obstacles.size());
  for (const auto& o : r.obstacles) {
    const Eigen::Quaternionf& q = o.orientation;
    std::printf("  %d: centre [%.3f %.3f %.3f] half extents [%.3f %.3f %.3f] orientation (x y z w) [%.3f %.3f %.3f %.3f], "
                "%zu points, group %d\n",
                o.id, o.centre.x(), o.centre.y(), o.centre.z(), o.half_extents.x(), o.half_extents.y(),
                o.half_extents.z(), q.x(), q.y(), q.z(), q.w(), o.indices.size(), o.group);
  }
  std::printf("time: %.4f s\n", seconds);
}

CloudParams Params(const std::string& config) {
  return config.empty() ? CloudParams{} : iplan::cloud::LoadCloudParams(config);
}

int RunObstacles(const ObstaclesOptions& o) {
  try {
    const CloudParams params = Params(o.config);
    const iplan::cloud::Cloud cloud = iplan::cloud::LoadPcd(o.pcd);
    iplan::cloud::ObstaclePipeline pipeline(params);
    const auto t0 = std::chrono::steady_clock::now();
    const Result r = pipeline.Process(cloud);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!o.labels_out.empty()) {
      std::string text;
      text.reserve(r.labels.size() * 2);
      for (const int l : r.labels) text += std::to_string(l) + "\n";
      iplan::core::WriteFileAtomically(o.labels_out, text);
    }
    if (o.json) std::cout << ResultJson(r, seconds) << std::endl;
    else PrintText(r, seconds);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "iplan cloud obstacles: " << e.what() << "\n";
    return 2;
  }
}

std::string Row(const std::string& name, const iplan::cloud::SceneScore& s) {
  char line[200];
  std::snprintf(line, sizeof line, "| %s | %d | %d | %d | %d | %.1f %% |", name.c_str(), s.objects, s.found,
                s.obstacles, s.false_obstacles,
                s.table_points ? 100.0 * s.table_labelled / s.table_points : 0.0);
  return line;
}

std::string Percent(int found, int objects) {
  char text[64];
  std::snprintf(text, sizeof text, "%.1f %% (%d/%d)", 100.0 * found / std::max(1, objects), found, objects);
  return text;
}

// Folds of scene indices from "stem stem ..." lists; every scene not named
// is a fold of its own (all of them without --cv-fold: leave one scene out).
std::vector<std::vector<int>> Folds(const std::vector<std::filesystem::path>& files,
                                    const std::vector<std::string>& lists) {
  std::vector<std::vector<int>> folds;
  std::vector<char> named(files.size(), 0);
  for (const std::string& list : lists) {
    std::istringstream words(list);
    std::vector<int> fold;
    for (std::string stem; words >> stem;) {
      const auto it = std::find_if(files.begin(), files.end(), [&](const auto& f) { return f.stem() == stem; });
      if (it == files.end()) throw std::runtime_error("--cv-fold: no scene '" + stem + "' in the folder");
      const int k = static_cast<int>(it - files.begin());
      if (named[k]) throw std::runtime_error("--cv-fold: scene '" + stem + "' named twice");
      named[k] = 1;
      fold.push_back(k);
    }
    if (fold.empty()) throw std::runtime_error("--cv-fold: an empty fold");
    folds.push_back(fold);
  }
  for (std::size_t k = 0; k < files.size(); ++k)
    if (!named[k]) folds.push_back({static_cast<int>(k)});
  return folds;
}

// Every setting of the grid on every scene, then the cross-validated choice.
void CrossValidateGrid(const EvalOptions& o, const CloudParams& base, const std::vector<std::filesystem::path>& files) {
  const auto grid = iplan::cloud::LoadCloudParamsGrid(o.cv, base);
  const auto folds = Folds(files, o.cv_folds);
  std::vector<std::vector<iplan::cloud::SceneScore>> scores(files.size());
  for (std::size_t s = 0; s < files.size(); ++s) {
    const iplan::cloud::Cloud cloud = iplan::cloud::LoadPcd(files[s].string());
    for (const auto& [name, params] : grid) {
      iplan::cloud::ObstaclePipeline pipeline(params);
      scores[s].push_back(iplan::cloud::ScoreScene(cloud.label, pipeline.Process(cloud).labels));
    }
  }
  const iplan::cloud::CrossValidation cv = iplan::cloud::CrossValidate(scores, folds);
  std::printf("\ncross-validation: %zu settings (%s), %zu folds; each fold's setting chosen on the other scenes\n\n",
              grid.size(), o.cv.c_str(), folds.size());
  std::printf("| held out | chosen setting | objects | found | false |\n|---|---|---|---|---|\n");
  for (const auto& f : cv.folds) {
    std::string names;
    for (const int s : f.scenes) names += (names.empty() ? "" : " ") + files[s].stem().string();
    std::printf("| %s | %s | %d | %d | %d |\n", names.c_str(), grid[f.chosen].first.c_str(), f.score.objects,
                f.score.found, f.score.false_obstacles);
  }
  std::printf("cross-validated: recall %s, false obstacles %.2f per scene\n",
              Percent(cv.held_out.found, cv.held_out.objects).c_str(),
              static_cast<double>(cv.held_out.false_obstacles) / files.size());
  std::printf("chosen on all scenes (tuned on them): %s: recall %s, false obstacles %.2f per scene\n",
              grid[cv.chosen_all].first.c_str(), Percent(cv.all.found, cv.all.objects).c_str(),
              static_cast<double>(cv.all.false_obstacles) / files.size());
}

int RunEval(const EvalOptions& o) {
  try {
    const CloudParams params = Params(o.config);
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(o.dir))
      if (e.path().extension() == ".pcd") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) throw std::runtime_error(o.dir + ": no .pcd files");
    iplan::cloud::ObstaclePipeline ours(params);
    iplan::cloud::SceneScore total_ours, total_textbook;
    std::cout << "| scene | objects | found (ours) | obstacles | false | table | found (textbook) | "
                 "obstacles | false | table |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& f : files) {
      const iplan::cloud::Cloud cloud = iplan::cloud::LoadPcd(f.string());
      if (cloud.label.empty()) throw std::runtime_error(f.string() + ": no label field (ground truth)");
      const auto a = iplan::cloud::ScoreScene(cloud.label, ours.Process(cloud).labels);
      const auto b = iplan::cloud::ScoreScene(cloud.label, iplan::cloud::TextbookPipeline(cloud, params).labels);
      total_ours = iplan::cloud::Add(total_ours, a);
      total_textbook = iplan::cloud::Add(total_textbook, b);
      const std::string rb = Row("", b);
      std::cout << Row(f.stem().string(), a) << rb.substr(rb.find('|', 5) + 1) << "\n";
    }
    const std::string rb = Row("", total_textbook);
    std::cout << Row("total", total_ours) << rb.substr(rb.find('|', 5) + 1) << "\n";
    auto summary = [&](const char* name, const iplan::cloud::SceneScore& s) {
      std::printf("%s: recall %.1f %% (%d/%d), false obstacles %.2f per scene, table %.2f %%\n", name,
                  100.0 * s.found / std::max(1, s.objects), s.found, s.objects,
                  static_cast<double>(s.false_obstacles) / files.size(),
                  s.table_points ? 100.0 * s.table_labelled / s.table_points : 0.0);
    };
    summary("ours", total_ours);
    summary("textbook", total_textbook);
    if (!o.cv.empty()) CrossValidateGrid(o, params, files);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "iplan cloud eval: " << e.what() << "\n";
    return 2;
  }
}

const bool kRegistered = iplan::cli::RegisterCommand("cloud", [](CLI::App& app) {
  CLI::App* cloud = app.add_subcommand("cloud", "Depth-camera point clouds (docs/perception-clouds.md).");
  cloud->require_subcommand(1);

  auto o = std::make_shared<ObstaclesOptions>();
  CLI::App* obs = cloud->add_subcommand(
      "obstacles",
      "Table plane and obstacles of one recorded cloud (sensor frame, metres).\n"
      "--json prints one line {\"table\":{\"normal\":[..],\"offset\":d,\"points\":n},\"obstacles\":"
      "[{\"id\":k,\"centre\":[..],\"half_extents\":[..],\"points\":n,\"orientation\":[x,y,z,w],\"group\":g},...],"
      "\"time_s\":t}:\nan oriented box per obstacle (half extents along its own axes, z along the table normal).\n"
      "Exit code 0 on success, 2 on bad input (unreadable file, bad config).");
  obs->add_option("--pcd", o->pcd, "PCD file (x y z [rgb|rgba] [label])")->required();
  obs->add_flag("--json", o->json, "print one JSON line instead of text");
  obs->add_option("--labels-out", o->labels_out,
                  "write one label per input point, file order, one per line: 0 removed or invalid, "
                  "1 table, k >= 2 obstacle k-1");
  obs->add_option("--config", o->config, "pipeline parameters YAML (config/cloud_pipeline.yaml; default: built-in)");
  obs->callback([o] { iplan::cli::SetExitCode(RunObstacles(*o)); });

  auto e = std::make_shared<EvalOptions>();
  CLI::App* ev = cloud->add_subcommand(
      "eval",
      "Scores our pipeline and the textbook PCL pipeline against the per-point ground truth\n"
      "(mOSD labels) of every .pcd file in a folder; prints a Markdown table per scene and totals.");
  ev->add_option("--dir", e->dir, "folder of labelled PCD files")->required();
  ev->add_option("--config", e->config, "pipeline parameters YAML (default: built-in)");
  ev->add_option("--cv", e->cv,
                 "also cross-validate a grid of settings (YAML: key: [values...], applied to --config): "
                 "each fold's setting chosen on the other scenes (objects found minus false obstacles)");
  ev->add_option("--cv-fold", e->cv_folds,
                 "scenes held out together, as file stems \"learn0 learn1\" (repeatable); every scene not "
                 "named is a fold of its own (none named: leave one scene out)")
      ->needs(ev->get_option("--cv"));
  ev->callback([e] { iplan::cli::SetExitCode(RunEval(*e)); });
});

}  // namespace
