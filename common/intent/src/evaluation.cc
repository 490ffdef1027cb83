#include "iplan/intent/evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <nlohmann/json.hpp>

#include "iplan/intent/belief_filter.h"
#include "iplan/intent/coverage_adapter.h"
#include "iplan/intent/kinematic_baseline.h"

namespace iplan::intent {
namespace {

// Chi-square quantile with 3 degrees of freedom at 0.95.
constexpr double kChi2Dof3P95 = 7.815;

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

// PredictIntent, timing every call (the report's inference percentiles).
struct TimedPredictor {
  const IntentModel& model;
  JointMixture pred;
  std::vector<double> times_ms;

  void operator()(const Eigen::MatrixXd& window) {
    const auto t0 = std::chrono::steady_clock::now();
    PredictIntent(model, window, &pred);
    times_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
};

void CheckEvalParams(const EvalParams& params) {
  if (params.fractions.empty() || params.forecast_stride < 1) {
    throw std::invalid_argument("EvalParams: need fractions and forecast_stride >= 1");
  }
  if (params.velocity_frames.empty() ||
      *std::min_element(params.velocity_frames.begin(), params.velocity_frames.end()) < 1) {
    throw std::invalid_argument("EvalParams: velocity_frames must be non-empty with entries >= 1");
  }
}

// Model action ids; throws for a track whose action the model does not know.
std::map<std::string, int> ActionIds(const IntentModel& model, const std::vector<Track>& tracks) {
  std::map<std::string, int> action_id;
  for (size_t c = 0; c < model.actions.size(); ++c) action_id[model.actions[c]] = static_cast<int>(c);
  for (const Track& t : tracks) {
    for (const std::string& a : t.frame_actions.empty() ? std::vector<std::string>{t.action} : t.frame_actions) {
      if (action_id.count(a) == 0) {
        throw std::invalid_argument("evaluation data contain action '" + a + "' (sequence " + t.sequence_id +
                                    ") that the model was not trained on");
      }
    }
  }
  return action_id;
}

// Accuracy: as online, the model's belief filter combines the windows
// ending at every frame of the observed prefix (one update per model frame).
void ScoreAccuracy(const std::vector<Track>& tracks, const std::map<std::string, int>& action_id,
                   const EvalParams& params, TimedPredictor& timed_predict, EvalReport* report) {
  const IntentModel& model = timed_predict.model;
  const JointMixture& pred = timed_predict.pred;
  EvalReport& r = *report;
  const int C = static_cast<int>(model.actions.size());
  const int T = model.config.window;
  const double rate = model.config.rate;
  BeliefFilter filter(C, model.classifier.belief);
  Eigen::VectorXd window_p(C);
  for (const Track& t : tracks) {
    const int n = static_cast<int>(t.positions.rows());
    std::vector<int> ends(params.fractions.size());
    for (size_t fi = 0; fi < params.fractions.size(); ++fi) {
      ends[fi] = std::max(1, static_cast<int>(std::ceil(params.fractions[fi] * n - 1e-9))) - 1;
    }
    const int last = *std::max_element(ends.begin(), ends.end());
    std::vector<Eigen::VectorXd> beliefs(static_cast<size_t>(last) + 1);
    filter.Reset();
    for (int e = 0; e <= last; ++e) {
      // The observed frames of the window (not padded), as the service has them.
      const int first = std::max(0, e - T + 1);
      const Eigen::MatrixXd window = t.positions.middleRows(first, e - first + 1);
      timed_predict(window);  // as the service: PredictIntent, then the filter
      for (int c = 0; c < C; ++c) window_p(c) = pred.probabilities[c];
      filter.UpdateWithWindow(window_p, window, T, e / rate);
      beliefs[e] = filter.probabilities();
    }
    for (size_t fi = 0; fi < params.fractions.size(); ++fi) {
      const Eigen::VectorXd& b = beliefs[ends[fi]];
      // The action being done at the end of the observed prefix.
      const int truth = action_id.at(ActionAt(t, ends[fi]));
      Eigen::Index guess = 0;
      b.maxCoeff(&guess);
      if (guess == truth) r.accuracy[fi] += 1.0;
      r.mean_true_probability[fi] += b(truth);
      if (fi + 1 == params.fractions.size()) r.confusion(truth, guess) += 1;
    }
  }
  for (size_t fi = 0; fi < params.fractions.size(); ++fi) {
    r.accuracy[fi] /= std::max(1, r.num_sequences);
    r.mean_true_probability[fi] /= std::max(1, r.num_sequences);
  }
}

// Sums over the forecast windows (divided by windows x joints at the end):
// per step k the model's joint error em, holding the current pose ep, and
// per L of velocity_frames the least-squares line ev and its current value
// es (V, H); the mixture-mean errors inside the 95 % ellipsoid.
struct ForecastSums {
  std::vector<double> em, ep;
  Eigen::MatrixXd ev, es;
  long inside = 0, total = 0;
};

// What one forecast window gives: the moment-matched mixture per (step k,
// joint j) at k * J + j, whether the truth is inside its 95 % ellipsoid, and
// the least-squares lines per L (position, velocity; V each).
struct WindowForecast {
  std::vector<JointGaussian> combined;
  std::vector<bool> inside;
  std::vector<Eigen::VectorXd> line_p, line_v;
};

// A reported horizon as steps: between step k (>= 1) and k + 1, weight a of k + 1.
struct HorizonSteps {
  double horizon_s = 0.0;
  int k = 0;
  double a = 0.0;
};

std::vector<HorizonSteps> ReportSteps(const EvalParams& params, double rate, int H) {
  std::vector<HorizonSteps> out;
  for (double h : params.report_horizons) {
    const double s = h * rate;
    int k = static_cast<int>(std::floor(s + 1e-9));
    double a = s - k;
    if (a < 1e-9) a = 0.0;
    if (k < 1 || (a > 0.0 ? k + 1 : k) > H) continue;
    out.push_back({h, k, a});
  }
  return out;
}

// Sums of a joint subset at the report horizons (R) and, for the lines, per
// L (V, R); coverage over every step.
struct SubsetSums {
  Eigen::VectorXd model, hold;
  Eigen::MatrixXd line;
  long samples = 0, inside = 0, total = 0;
};

// The mixture of the window ending at row e against the recorded future after row e.
void AddModelErrors(const Track& t, int e, const WindowForecast& w, int H, int J, ForecastSums* s) {
  const Eigen::RowVectorXd now = t.positions.row(e);
  for (int k = 0; k < H; ++k) {
    const Eigen::RowVectorXd truth = t.positions.row(e + k + 1);
    for (int j = 0; j < J; ++j) {
      const Eigen::Vector3d p_true = truth.segment<3>(3 * j).transpose();
      s->em[k] += (p_true - w.combined[k * J + j].mean).norm();
      s->ep[k] += (p_true - now.segment<3>(3 * j).transpose()).norm();
      if (w.inside[k * J + j]) ++s->inside;
      ++s->total;
    }
  }
}

// Least-squares baselines over the recorded frames up to e.
void AddLineBaselineErrors(const Track& t, int e, const WindowForecast& w, double rate, int H,
                           int J, ForecastSums* s) {
  for (size_t v = 0; v < w.line_p.size(); ++v) {
    for (int k = 0; k < H; ++k) {
      const Eigen::RowVectorXd truth = t.positions.row(e + k + 1);
      const double ahead = (k + 1) / rate;
      for (int j = 0; j < J; ++j) {
        const Eigen::Vector3d p_true = truth.segment<3>(3 * j).transpose();
        const Eigen::Vector3d p_line = w.line_p[v].segment<3>(3 * j);
        s->ev(v, k) += (p_true - p_line - ahead * w.line_v[v].segment<3>(3 * j)).norm();
        s->es(v, k) += (p_true - p_line).norm();
      }
    }
  }
}

// Joint j of the window ending at e at the report horizons, into `s`.
void AddSubsetErrors(const Track& t, int e, int j, const WindowForecast& w,
                     const std::vector<HorizonSteps>& steps, int H, int J, SubsetSums* s) {
  const Eigen::Vector3d now = t.positions.block<1, 3>(e, 3 * j).transpose();
  for (size_t r = 0; r < steps.size(); ++r) {
    const HorizonSteps& h = steps[r];
    const int k2 = h.a > 0.0 ? h.k + 1 : h.k;
    const Eigen::Vector3d truth = (1.0 - h.a) * t.positions.block<1, 3>(e + h.k, 3 * j).transpose() +
                                  h.a * t.positions.block<1, 3>(e + k2, 3 * j).transpose();
    const Eigen::Vector3d mean = (1.0 - h.a) * w.combined[(h.k - 1) * J + j].mean +
                                 h.a * w.combined[(k2 - 1) * J + j].mean;
    s->model(r) += (truth - mean).norm();
    s->hold(r) += (truth - now).norm();
    for (size_t v = 0; v < w.line_p.size(); ++v) {
      s->line(v, r) += (truth - w.line_p[v].segment<3>(3 * j) - h.horizon_s * w.line_v[v].segment<3>(3 * j)).norm();
    }
  }
  for (int k = 0; k < H; ++k) s->inside += w.inside[k * J + j] ? 1 : 0;
  s->total += H;
  ++s->samples;
}

// The subset's averages, the best L per horizon.
JointForecastErrors FinishSubset(const SubsetSums& s, const std::vector<HorizonSteps>& steps,
                                 const EvalParams& params, std::vector<std::string> joints) {
  JointForecastErrors out;
  out.joints = std::move(joints);
  out.num_samples = s.samples;
  if (s.samples == 0) return out;
  const double n = static_cast<double>(s.samples);
  for (size_t r = 0; r < steps.size(); ++r) {
    HorizonError h;
    h.horizon_s = steps[r].horizon_s;
    h.model = s.model(r) / n;
    h.const_position = s.hold(r) / n;
    Eigen::Index best = 0;
    h.const_velocity = s.line.col(r).minCoeff(&best) / n;
    h.const_velocity_frames = params.velocity_frames[best];
    out.at.push_back(h);
  }
  out.coverage95 = static_cast<double>(s.inside) / std::max<long>(1, s.total);
  return out;
}

// The model's hand joints (all joints when it names none) as indices.
std::vector<int> HandIndices(const IntentModel& model) {
  const std::vector<std::string>& joints = model.config.joints.joints;
  std::vector<int> out;
  for (const std::string& h : model.config.joints.hands) {
    out.push_back(static_cast<int>(std::find(joints.begin(), joints.end(), h) - joints.begin()));
  }
  if (out.empty()) {
    for (size_t j = 0; j < joints.size(); ++j) out.push_back(static_cast<int>(j));
  }
  return out;
}

// The published mixture `pred` of the window ending at row e (its
// components weighted by the belief and scaled by the coverage adapter, as
// the intent service publishes it) and the lines through the recorded frames
// up to e.
void ForecastWindow(const Track& t, int e, const EvalParams& params, const IntentModel& model,
                    const JointMixture& pred, WindowForecast* w) {
  const int J = static_cast<int>(model.config.joints.joints.size());
  const int H = model.config.horizon;
  w->combined.resize(static_cast<size_t>(H) * J);
  w->inside.resize(static_cast<size_t>(H) * J);
  for (int k = 0; k < H; ++k) {
    for (int j = 0; j < J; ++j) {
      const JointGaussian g = pred.Combined(k, j);
      const Eigen::Vector3d err = t.positions.block<1, 3>(e + k + 1, 3 * j).transpose() - g.mean;
      w->combined[k * J + j] = g;
      w->inside[k * J + j] = err.dot(g.covariance.ldlt().solve(err)) <= kChi2Dof3P95;
    }
  }
  const size_t V = params.velocity_frames.size();
  w->line_p.resize(V);
  w->line_v.resize(V);
  for (size_t v = 0; v < V; ++v) {
    FitLine(t.positions.topRows(e + 1), params.velocity_frames[v], model.config.rate, &w->line_p[v],
            &w->line_v[v]);
  }
}

// The per-step averages of the sums.
void FinishSteps(const ForecastSums& s, const EvalParams& params, int H, double denom, EvalReport* r) {
  r->velocity_frames = params.velocity_frames;
  r->error_const_velocity_by_frames = s.ev / denom;
  r->error_smoothed_position_by_frames = s.es / denom;
  for (int k = 0; k < H; ++k) {
    r->error_model.push_back(s.em[k] / denom);
    r->error_const_position.push_back(s.ep[k] / denom);
    Eigen::Index best_v = 0, best_s = 0;
    r->error_const_velocity.push_back(r->error_const_velocity_by_frames.col(k).minCoeff(&best_v));
    r->const_velocity_frames.push_back(params.velocity_frames[best_v]);
    r->error_smoothed_position.push_back(r->error_smoothed_position_by_frames.col(k).minCoeff(&best_s));
    r->smoothed_position_frames.push_back(params.velocity_frames[best_s]);
  }
  r->coverage95 = s.total > 0 ? static_cast<double>(s.inside) / s.total : 0.0;
}

// Forecasts: every joint per step, the hands and the reaching joints at the report horizons.
void ScoreForecasts(const std::vector<Track>& tracks, const EvalParams& params,
                    TimedPredictor& timed_predict, EvalReport* report) {
  const IntentModel& model = timed_predict.model;
  EvalReport& r = *report;
  const int J = static_cast<int>(model.config.joints.joints.size());
  const int H = model.config.horizon;
  const double rate = model.config.rate;
  r.horizon_s.resize(H);
  for (int k = 0; k < H; ++k) r.horizon_s[k] = (k + 1) / rate;
  const int V = static_cast<int>(params.velocity_frames.size());
  ForecastSums s{std::vector<double>(H, 0.0), std::vector<double>(H, 0.0),
                 Eigen::MatrixXd::Zero(V, H), Eigen::MatrixXd::Zero(V, H), 0, 0};
  const std::vector<HorizonSteps> steps = ReportSteps(params, rate, H);
  const Eigen::Index R = static_cast<Eigen::Index>(steps.size());
  const SubsetSums zero{Eigen::VectorXd::Zero(R), Eigen::VectorXd::Zero(R), Eigen::MatrixXd::Zero(V, R), 0, 0, 0};
  SubsetSums hand = zero, reaching = zero;
  const std::vector<int> hands = HandIndices(model);
  std::vector<bool> reached(J, false);
  WindowForecast w;
  // The tracks are people one after another in one cell: with carry_over
  // each starts from the scales the one before ended with, as the intent
  // service starts a new body; without, from 1 (the model's).
  Eigen::VectorXd cell_scales = Eigen::VectorXd::Ones(J);
  for (const Track& t : tracks) {
    const int n = static_cast<int>(t.positions.rows());
    // As online: every frame is predicted, updates the belief and the
    // coverage adapter; the forecast windows are scored on what is published.
    BeliefFilter filter(static_cast<int>(model.actions.size()), model.classifier.belief);
    CoverageAdapter coverage(J, H, rate, params.coverage);
    coverage.Reset(cell_scales);
    Eigen::VectorXd window_p(static_cast<Eigen::Index>(model.actions.size()));
    JointMixture& pred = timed_predict.pred;
    for (int e = 0; e + H <= n - 1; ++e) {
      const int first = std::max(0, e - model.config.window + 1);
      const Eigen::MatrixXd window = t.positions.middleRows(first, e - first + 1);
      timed_predict(window);
      for (Eigen::Index c = 0; c < window_p.size(); ++c) window_p(c) = pred.probabilities[c];
      filter.UpdateWithWindow(window_p, window, model.config.window, e / rate);
      for (Eigen::Index c = 0; c < window_p.size(); ++c) pred.probabilities[c] = filter.probabilities()(c);
      coverage.Observe(e / rate, t.positions.row(e).transpose());
      coverage.Apply(&pred);
      coverage.Record(e / rate, pred);
      if (e % params.forecast_stride != 0) continue;
      ForecastWindow(t, e, params, model, pred, &w);
      ++r.num_forecast_windows;
      AddModelErrors(t, e, w, H, J, &s);
      AddLineBaselineErrors(t, e, w, rate, H, J, &s);
      for (int j : hands) AddSubsetErrors(t, e, j, w, steps, H, J, &hand);
      for (int j = 0; j < J && t.reaching.size() > 0; ++j) {
        if (!t.reaching(e, j)) continue;
        AddSubsetErrors(t, e, j, w, steps, H, J, &reaching);
        reached[j] = true;
      }
    }
    if (params.coverage.carry_over) cell_scales = coverage.variance_scales();
  }
  FinishSteps(s, params, H, std::max(1.0, static_cast<double>(r.num_forecast_windows) * J), &r);
  std::vector<std::string> hand_names;
  for (int j : hands) hand_names.push_back(model.config.joints.joints[j]);
  r.hand = FinishSubset(hand, steps, params, hand_names);
  std::vector<std::string> reaching_names;
  for (int j = 0; j < J; ++j) {
    if (reached[j]) reaching_names.push_back(model.config.joints.joints[j]);
  }
  r.reaching = FinishSubset(reaching, steps, params, reaching_names);
}

// One subset as JSON (null when it was not scored).
nlohmann::ordered_json SubsetJson(const JointForecastErrors& f) {
  if (f.num_samples == 0 && f.joints.empty()) return nullptr;
  nlohmann::ordered_json j;
  j["joints"] = f.joints;
  j["samples"] = f.num_samples;
  j["error_m"] = nlohmann::ordered_json::object();
  for (const HorizonError& h : f.at) {
    j["error_m"][FormatKey(h.horizon_s)] = {{"model", h.model},
                                            {"const_position", h.const_position},
                                            {"const_velocity", h.const_velocity},
                                            {"const_velocity_frames", h.const_velocity_frames},
                                            {"ratio_to_best_baseline", h.RatioToBestBaseline()}};
  }
  j["coverage95"] = f.coverage95;
  return j;
}

// One subset as text lines.
void SubsetText(const std::string& title, const JointForecastErrors& f, std::ostream& os) {
  if (f.num_samples == 0) return;
  os << title << " (";
  for (size_t i = 0; i < f.joints.size(); ++i) os << (i ? ", " : "") << f.joints[i];
  os << "; " << f.num_samples << " window x joint pairs), error [m] at:\n"
     << "  horizon_s   model  const_pos  const_vel (L)  model/best_baseline\n";
  for (const HorizonError& h : f.at) {
    os << "  " << std::setprecision(3) << std::setw(9) << h.horizon_s << std::setw(8) << h.model
       << std::setw(11) << h.const_position << std::setw(11) << h.const_velocity << " (" << std::setw(2)
       << h.const_velocity_frames << ")" << std::setw(12) << std::setprecision(2) << h.RatioToBestBaseline()
       << "\n";
  }
  os << "  95 % ellipsoid coverage (every step): " << std::setprecision(1) << 100.0 * f.coverage95 << " %\n";
}

}  // namespace

double HorizonError::RatioToBestBaseline() const {
  return model / std::max(std::min(const_position, const_velocity), 1e-12);
}

std::string FormatKey(double value) {
  std::ostringstream os;
  os << std::setprecision(3) << value;
  std::string s = os.str();
  if (s.find('.') == std::string::npos && s.find('e') == std::string::npos) s += ".0";
  return s;
}

EvalReport EvaluateIntentModel(const IntentModel& model, const SkeletonDataset& data,
                               const EvalParams& params) {
  CheckEvalParams(params);
  const std::vector<Track> tracks = MakeTracks(data, model.config, params.max_gap);
  const std::map<std::string, int> action_id = ActionIds(model, tracks);
  const int C = static_cast<int>(model.actions.size());

  EvalReport r;
  r.actions = model.actions;
  r.fractions = params.fractions;
  r.accuracy.assign(params.fractions.size(), 0.0);
  r.mean_true_probability.assign(params.fractions.size(), 0.0);
  r.confusion = Eigen::MatrixXi::Zero(C, C);
  r.num_sequences = static_cast<int>(tracks.size());
  TimedPredictor timed_predict{model, {}, {}};
  ScoreAccuracy(tracks, action_id, params, timed_predict, &r);
  ScoreForecasts(tracks, params, timed_predict, &r);
  r.inference_p50_ms = Percentile(timed_predict.times_ms, 0.5);
  r.inference_p99_ms = Percentile(timed_predict.times_ms, 0.99);
  r.num_inference_calls = static_cast<int>(timed_predict.times_ms.size());
  return r;
}

std::string EvalReportToJson(const EvalReport& r) {
  nlohmann::ordered_json j;
  for (size_t i = 0; i < r.fractions.size(); ++i) j["accuracy"][FormatKey(r.fractions[i])] = r.accuracy[i];
  for (size_t i = 0; i < r.fractions.size(); ++i) {
    j["mean_true_probability"][FormatKey(r.fractions[i])] = r.mean_true_probability[i];
  }
  j["error_m"] = nlohmann::ordered_json::object();
  if (r.num_forecast_windows > 0) {
    for (size_t k = 0; k < r.horizon_s.size(); ++k) {
      j["error_m"][FormatKey(r.horizon_s[k])] = {
          {"model", r.error_model[k]},
          {"const_position", r.error_const_position[k]},
          {"const_velocity", r.error_const_velocity[k]},
          {"const_velocity_frames", r.const_velocity_frames[k]},
          {"smoothed_position", r.error_smoothed_position[k]},
          {"smoothed_position_frames", r.smoothed_position_frames[k]}};
    }
    for (size_t v = 0; v < r.velocity_frames.size(); ++v) {
      const std::string key = std::to_string(r.velocity_frames[v]);
      for (size_t k = 0; k < r.horizon_s.size(); ++k) {
        const std::string h = FormatKey(r.horizon_s[k]);
        j["const_velocity_by_frames"][key][h] = r.error_const_velocity_by_frames(v, k);
        j["smoothed_position_by_frames"][key][h] = r.error_smoothed_position_by_frames(v, k);
      }
    }
    j["coverage95"] = r.coverage95;
  } else {
    j["coverage95"] = nullptr;
  }
  j["hand"] = SubsetJson(r.hand);
  j["reaching"] = r.reaching.num_samples > 0 ? SubsetJson(r.reaching) : nullptr;
  j["inference_ms"] = {{"p50", r.inference_p50_ms}, {"p99", r.inference_p99_ms}};
  j["actions"] = r.actions;
  std::vector<std::vector<int>> conf(r.confusion.rows());
  for (Eigen::Index a = 0; a < r.confusion.rows(); ++a) {
    for (Eigen::Index b = 0; b < r.confusion.cols(); ++b) conf[a].push_back(r.confusion(a, b));
  }
  j["confusion"] = conf;
  j["num_sequences"] = r.num_sequences;
  j["num_forecast_windows"] = r.num_forecast_windows;
  j["num_inference_calls"] = r.num_inference_calls;
  return j.dump(2);
}

std::string EvalReportToText(const EvalReport& r) {
  std::ostringstream os;
  os << std::fixed;
  os << "sequences: " << r.num_sequences << "\n";
  os << "accuracy by observed fraction (mean p(true action)):\n";
  for (size_t i = 0; i < r.fractions.size(); ++i) {
    os << "  " << std::setw(4) << std::setprecision(0) << 100.0 * r.fractions[i] << " %: "
       << std::setprecision(1) << std::setw(5) << 100.0 * r.accuracy[i] << " %  ("
       << std::setprecision(3) << r.mean_true_probability[i] << ")\n";
  }
  os << "confusion matrix at " << std::setprecision(0) << 100.0 * r.fractions.back()
     << " % observed (row: true, column: predicted):\n";
  size_t width = 6;
  for (const std::string& a : r.actions) width = std::max(width, a.size() + 1);
  for (Eigen::Index a = 0; a < r.confusion.rows(); ++a) {
    os << "  " << std::left << std::setw(static_cast<int>(width)) << r.actions[a] << std::right;
    for (Eigen::Index b = 0; b < r.confusion.cols(); ++b) os << std::setw(4) << r.confusion(a, b);
    os << "\n";
  }
  if (r.num_forecast_windows > 0) {
    os << "forecast windows: " << r.num_forecast_windows << "\n";
    os << "mean joint position error [m] by horizon:\n";
    os << "  (const_vel: least-squares line through the last L frames, the best L per horizon;\n"
          "   smoothed_pos: hold that line's current value, a diagnostic)\n";
    os << "  horizon_s   model  const_pos  const_vel (L)  smoothed_pos (L)  model/best_baseline\n";
    for (size_t k = 0; k < r.horizon_s.size(); ++k) {
      const double best = std::min(r.error_const_position[k], r.error_const_velocity[k]);
      os << "  " << std::setprecision(3) << std::setw(9) << r.horizon_s[k] << std::setw(8)
         << r.error_model[k] << std::setw(11) << r.error_const_position[k] << std::setw(11)
         << r.error_const_velocity[k] << " (" << std::setw(2) << r.const_velocity_frames[k] << ")"
         << std::setw(14) << r.error_smoothed_position[k] << " (" << std::setw(2)
         << r.smoothed_position_frames[k] << ")" << std::setw(12) << std::setprecision(2)
         << r.error_model[k] / std::max(best, 1e-12) << "\n";
    }
    os << "95 % ellipsoid coverage: " << std::setprecision(1) << 100.0 * r.coverage95 << " %\n";
    SubsetText("hand", r.hand, os);
    SubsetText("reaching", r.reaching, os);
  } else {
    os << "forecast windows: 0 (no sequence has a recorded future of the full horizon)\n";
  }
  os << "inference per frame: p50 " << std::setprecision(3) << r.inference_p50_ms
     << " ms, p99 " << r.inference_p99_ms << " ms (" << r.num_inference_calls << " calls)\n";
  return os.str();
}

}  // namespace iplan::intent
