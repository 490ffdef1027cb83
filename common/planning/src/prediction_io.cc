#include "iplan/planning/prediction_io.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace iplan::planning {

PredictionFile ParsePredictionJson(const std::string& text, const collision::HumanBodyModel& body,
                                   const std::string& source) {
  using nlohmann::json;
  auto fail = [&](const std::string& what) { throw std::runtime_error(source + ": " + what); };
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    fail(std::string("invalid JSON: ") + e.what());
  }
  if (!j.is_object()) fail("top level must be an object");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "dt" && it.key() != "start_time" && it.key() != "joints" && it.key() != "actions")
      fail("unknown key '" + it.key() + "'");
  PredictionFile out;
  if (!j.contains("dt") || !j["dt"].is_number()) fail("'dt' (number, s) is required");
  out.dt = j["dt"].get<double>();
  if (!(out.dt > 0.0) || !std::isfinite(out.dt)) fail("'dt' must be > 0, got " + j["dt"].dump());
  if (j.contains("start_time")) {
    if (!j["start_time"].is_number()) fail("'start_time' must be a number");
    out.start_time = j["start_time"].get<double>();
  }
  if (!j.contains("joints") || !j["joints"].is_array()) fail("'joints' (array of names) is required");
  std::vector<std::string> names;
  for (const auto& n : j["joints"]) {
    if (!n.is_string()) fail("'joints' entries must be strings, got " + n.dump());
    names.push_back(n.get<std::string>());
  }
  // Map body joints to file columns.
  const auto& body_joints = body.params().joints;
  std::vector<int> column(body_joints.size(), -1);
  for (std::size_t b = 0; b < body_joints.size(); ++b) {
    for (std::size_t f = 0; f < names.size(); ++f)
      if (names[f] == body_joints[b]) column[b] = static_cast<int>(f);
    if (column[b] < 0) fail("joint '" + body_joints[b] + "' of the body model is missing in 'joints'");
  }
  if (!j.contains("actions") || !j["actions"].is_array() || j["actions"].empty())
    fail("'actions' (non-empty array) is required");
  const auto& actions = j["actions"];
  const int num_actions = static_cast<int>(actions.size());
  int num_steps = -1;
  for (int c = 0; c < num_actions; ++c) {
    const auto& a = actions[c];
    if (!a.is_object() || !a.contains("steps") || !a["steps"].is_array() || a["steps"].empty())
      fail("actions[" + std::to_string(c) + "] needs a non-empty 'steps' array");
    const int s = static_cast<int>(a["steps"].size());
    if (num_steps >= 0 && s != num_steps)
      fail("actions[" + std::to_string(c) + "] has " + std::to_string(s) + " steps, actions[0] has " +
           std::to_string(num_steps));
    num_steps = s;
  }
  out.prediction = std::make_unique<collision::HumanPrediction>(body.MakePrediction(num_actions, num_steps));
  const int nj = body.num_joints();
  Eigen::Matrix3Xd means(3, nj);
  std::vector<Eigen::Matrix3d> covs(nj);
  double psum = 0.0;
  for (int c = 0; c < num_actions; ++c) {
    const auto& a = actions[c];
    const std::string where = "actions[" + std::to_string(c) + "]";
    for (auto it = a.begin(); it != a.end(); ++it)
      if (it.key() != "name" && it.key() != "probability" && it.key() != "steps")
        fail(where + ": unknown key '" + it.key() + "'");
    out.action_names.push_back(a.value("name", "action" + std::to_string(c)));
    if (!a.contains("probability") || !a["probability"].is_number())
      fail(where + ".probability (number) is required");
    const double p = a["probability"].get<double>();
    if (!(p >= 0.0 && p <= 1.0)) fail(where + ".probability must be in [0, 1], got " + a["probability"].dump());
    psum += p;
    out.prediction->set_action_probability(c, p);
    for (int s = 0; s < num_steps; ++s) {
      const auto& st = a["steps"][s];
      const std::string sw = where + ".steps[" + std::to_string(s) + "]";
      if (!st.is_object() || !st.contains("mean") || !st.contains("cov"))
        fail(sw + " needs 'mean' and 'cov'");
      for (auto it = st.begin(); it != st.end(); ++it)
        if (it.key() != "mean" && it.key() != "cov") fail(sw + ": unknown key '" + it.key() + "'");
      const auto& m = st["mean"];
      const auto& cv = st["cov"];
      if (!m.is_array() || m.size() != names.size() || !cv.is_array() || cv.size() != names.size())
        fail(sw + ": 'mean' and 'cov' need one entry per joint (" + std::to_string(names.size()) + ")");
      for (int b = 0; b < nj; ++b) {
        const auto& mj = m[column[b]];
        const auto& cj = cv[column[b]];
        if (!mj.is_array() || mj.size() != 3)
          fail(sw + ".mean of joint '" + body_joints[b] + "' must be [x, y, z], got " + mj.dump());
        if (!cj.is_array() || cj.size() != 9)
          fail(sw + ".cov of joint '" + body_joints[b] + "' must have 9 numbers, got " + cj.dump());
        for (int r = 0; r < 3; ++r) {
          if (!mj[r].is_number()) fail(sw + ".mean: not a number: " + mj.dump());
          means(r, b) = mj[r].get<double>();
        }
        for (int r = 0; r < 9; ++r) {
          if (!cj[r].is_number()) fail(sw + ".cov: not a number: " + cj.dump());
          covs[b](r / 3, r % 3) = cj[r].get<double>();
        }
        if (!means.col(b).allFinite() || !covs[b].allFinite() ||
            (covs[b] - covs[b].transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + covs[b].norm()))
          fail(sw + ": joint '" + body_joints[b] + "' has a non-finite mean or non-symmetric covariance " +
               cj.dump());
      }
      if (!body.FillPrediction(means, covs, c, s, out.prediction.get()))
        fail(sw + ": a sphere covariance is not positive definite (check the joint covariances)");
    }
  }
  if (psum > 1.0 + 1e-6) fail("action probabilities sum to " + std::to_string(psum) + " > 1");
  out.prediction->UpdateSummaries();
  return out;
}

PredictionFile LoadPredictionFile(const std::string& path, const collision::HumanBodyModel& body) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open prediction file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParsePredictionJson(ss.str(), body, path);
}

}  // namespace iplan::planning
