#include "iplan/planning/prediction_io.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace iplan::planning {

namespace {

using nlohmann::json;

// Parsing with errors that name the source (the file).
class PredictionParser {
 public:
  PredictionParser(const collision::HumanBodyModel& body, const std::string& source) : body_(body), source_(source) {}

  PredictionFile Parse(const std::string& text) {
    json j;
    try {
      j = json::parse(text);
    } catch (const json::exception& e) {
      Fail(std::string("invalid JSON: ") + e.what());
    }
    if (!j.is_object()) Fail("top level must be an object");
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.key() != "dt" && it.key() != "start_time" && it.key() != "joints" && it.key() != "actions")
        Fail("unknown key '" + it.key() + "'");
    PredictionFile out;
    ParseTiming(j, &out);
    MapJoints(j);
    const int num_steps = CountSteps(j);
    const auto& actions = j["actions"];
    const int num_actions = static_cast<int>(actions.size());
    out.prediction = std::make_unique<collision::HumanPrediction>(body_.MakePrediction(num_actions, num_steps));
    double psum = 0.0;
    for (int c = 0; c < num_actions; ++c) psum += ParseAction(actions[c], c, num_steps, &out);
    if (psum > 1.0 + 1e-6) Fail("action probabilities sum to " + std::to_string(psum) + " > 1");
    out.prediction->UpdateSummaries();
    return out;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw std::runtime_error(source_ + ": " + what); }

  void ParseTiming(const json& j, PredictionFile* out) const {
    if (!j.contains("dt") || !j["dt"].is_number()) Fail("'dt' (number, s) is required");
    out->dt = j["dt"].get<double>();
    if (!(out->dt > 0.0) || !std::isfinite(out->dt)) Fail("'dt' must be > 0, got " + j["dt"].dump());
    if (j.contains("start_time")) {
      if (!j["start_time"].is_number()) Fail("'start_time' must be a number");
      out->start_time = j["start_time"].get<double>();
    }
  }

  // The file's joint names and the column of each body joint.
  void MapJoints(const json& j) {
    if (!j.contains("joints") || !j["joints"].is_array()) Fail("'joints' (array of names) is required");
    for (const auto& n : j["joints"]) {
      if (!n.is_string()) Fail("'joints' entries must be strings, got " + n.dump());
      names_.push_back(n.get<std::string>());
    }
    const auto& body_joints = body_.params().joints;
    column_.assign(body_joints.size(), -1);
    for (std::size_t b = 0; b < body_joints.size(); ++b) {
      for (std::size_t f = 0; f < names_.size(); ++f)
        if (names_[f] == body_joints[b]) column_[b] = static_cast<int>(f);
      if (column_[b] < 0) Fail("joint '" + body_joints[b] + "' of the body model is missing in 'joints'");
    }
  }

  // The number of steps, the same for every action.
  int CountSteps(const json& j) const {
    if (!j.contains("actions") || !j["actions"].is_array() || j["actions"].empty())
      Fail("'actions' (non-empty array) is required");
    int num_steps = -1;
    for (std::size_t c = 0; c < j["actions"].size(); ++c) {
      const auto& a = j["actions"][c];
      if (!a.is_object() || !a.contains("steps") || !a["steps"].is_array() || a["steps"].empty())
        Fail("actions[" + std::to_string(c) + "] needs a non-empty 'steps' array");
      const int s = static_cast<int>(a["steps"].size());
      if (num_steps >= 0 && s != num_steps)
        Fail("actions[" + std::to_string(c) + "] has " + std::to_string(s) + " steps, actions[0] has " +
             std::to_string(num_steps));
      num_steps = s;
    }
    return num_steps;
  }

  // One action into out->prediction; returns its probability.
  double ParseAction(const json& a, int c, int num_steps, PredictionFile* out) {
    const std::string where = "actions[" + std::to_string(c) + "]";
    for (auto it = a.begin(); it != a.end(); ++it)
      if (it.key() != "name" && it.key() != "probability" && it.key() != "steps")
        Fail(where + ": unknown key '" + it.key() + "'");
    out->action_names.push_back(a.value("name", "action" + std::to_string(c)));
    if (!a.contains("probability") || !a["probability"].is_number()) Fail(where + ".probability (number) is required");
    const double p = a["probability"].get<double>();
    if (!(p >= 0.0 && p <= 1.0)) Fail(where + ".probability must be in [0, 1], got " + a["probability"].dump());
    out->prediction->set_action_probability(c, p);
    for (int s = 0; s < num_steps; ++s) ParseStep(a["steps"][s], where + ".steps[" + std::to_string(s) + "]", c, s, out);
    return p;
  }

  void ParseStep(const json& st, const std::string& sw, int c, int s, PredictionFile* out) {
    if (!st.is_object() || !st.contains("mean") || !st.contains("cov")) Fail(sw + " needs 'mean' and 'cov'");
    for (auto it = st.begin(); it != st.end(); ++it)
      if (it.key() != "mean" && it.key() != "cov") Fail(sw + ": unknown key '" + it.key() + "'");
    const auto& m = st["mean"];
    const auto& cv = st["cov"];
    if (!m.is_array() || m.size() != names_.size() || !cv.is_array() || cv.size() != names_.size())
      Fail(sw + ": 'mean' and 'cov' need one entry per joint (" + std::to_string(names_.size()) + ")");
    const auto& body_joints = body_.params().joints;
    const int nj = body_.num_joints();
    Eigen::Matrix3Xd means(3, nj);
    std::vector<Eigen::Matrix3d> covs(nj);
    for (int b = 0; b < nj; ++b) {
      const auto& mj = m[column_[b]];
      const auto& cj = cv[column_[b]];
      if (!mj.is_array() || mj.size() != 3)
        Fail(sw + ".mean of joint '" + body_joints[b] + "' must be [x, y, z], got " + mj.dump());
      if (!cj.is_array() || cj.size() != 9)
        Fail(sw + ".cov of joint '" + body_joints[b] + "' must have 9 numbers, got " + cj.dump());
      for (int r = 0; r < 3; ++r) {
        if (!mj[r].is_number()) Fail(sw + ".mean: not a number: " + mj.dump());
        means(r, b) = mj[r].get<double>();
      }
      for (int r = 0; r < 9; ++r) {
        if (!cj[r].is_number()) Fail(sw + ".cov: not a number: " + cj.dump());
        covs[b](r / 3, r % 3) = cj[r].get<double>();
      }
      if (!means.col(b).allFinite() || !covs[b].allFinite() ||
          (covs[b] - covs[b].transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + covs[b].norm()))
        Fail(sw + ": joint '" + body_joints[b] + "' has a non-finite mean or non-symmetric covariance " + cj.dump());
    }
    if (!body_.FillPrediction(means, covs, c, s, out->prediction.get()))
      Fail(sw + ": a sphere covariance is not positive definite (check the joint covariances)");
  }

  const collision::HumanBodyModel& body_;
  const std::string& source_;
  std::vector<std::string> names_;
  std::vector<int> column_;
};

}  // namespace

PredictionFile ParsePredictionJson(const std::string& text, const collision::HumanBodyModel& body,
                                   const std::string& source) {
  return PredictionParser(body, source).Parse(text);
}

PredictionFile LoadPredictionFile(const std::string& path, const collision::HumanBodyModel& body) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open prediction file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParsePredictionJson(ss.str(), body, path);
}

}  // namespace iplan::planning
