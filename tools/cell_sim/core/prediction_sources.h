// Internal to the benchmarks of services/cell_sim (interaction_benchmark.cc,
// cell_benchmark.cc): what each predictor feeds the planner and the
// collision-risk monitor, per skeleton frame of one person (a scenario's or
// an episode's), made lazily in frame order. Units: m, s; world frame W.
// Not thread-safe.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tools/cell_sim/core/interaction_benchmark.h"
#include "tools/cell_sim/core/scenario_draws.h"

namespace iplan::cell_sim::internal {

// The model's predictions of one scenario, made once (lazily, in frame
// order) and shared by every predictor's run: the estimator is fed every
// observed skeleton, as the intent service is.
class ModelTrack {
 public:
  ModelTrack(const BenchmarkSetup& setup, const PersonStream& person)
      : person_(person), estimator_(setup.intent_model, setup.estimator), joints_(setup.intent_model->config.joints.joints) {
    for (const auto& name : joints_) {
      const auto it = std::find(person.joint_names.begin(), person.joint_names.end(), name);
      if (it == person.joint_names.end()) {
        throw std::invalid_argument("the intent model's joint '" + name + "' is not a joint of the body model");
      }
      body_index_.push_back(static_cast<int>(it - person.joint_names.begin()));
    }
    frame_.body_id = 1;
    frame_.joints.resize(joints_.size());
    for (std::size_t j = 0; j < joints_.size(); ++j) frame_.joints[j].name = joints_[j];
  }

  const std::vector<std::string>& joints() const { return joints_; }
  int body_index(std::size_t model_joint) const { return body_index_[model_joint]; }

  const collision::JointMixture* At(int frame) {
    while (static_cast<int>(done_.size()) <= frame) Advance();
    return done_[static_cast<std::size_t>(frame)] ? &mixtures_[static_cast<std::size_t>(frame)] : nullptr;
  }
  // The model's within-action covariance sum_c p_c Sigma_c at (step, model joint).
  Eigen::Matrix3d WithinCovariance(int frame, int step, std::size_t joint) {
    const collision::JointMixture* m = At(frame);
    Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
    if (!m) return c;
    const std::size_t J = joints_.size();
    for (std::size_t a = 0; a < m->actions.size(); ++a) {
      c += m->probabilities[a] * m->covariances[a][static_cast<std::size_t>(step) * J + joint];
    }
    return c;
  }

 private:
  void Advance() {
    const int i = static_cast<int>(done_.size());
    const Eigen::Matrix3Xd& seen = person_.observed[static_cast<std::size_t>(i)];
    const int64_t t0 = SimTimeNs(person_.stamp(i));
    frame_.stamp = static_cast<double>(t0) * 1e-9;
    for (std::size_t j = 0; j < joints_.size(); ++j) frame_.joints[j].position = seen.col(body_index_[j]);
    const intent_service::FrameResult r = estimator_.Update(frame_, &mixture_);
    mixtures_.push_back(r.accepted() ? Stamped(mixture_, joints_, t0) : collision::JointMixture{});
    done_.push_back(r.accepted());
  }

  const PersonStream& person_;
  intent_service::IntentEstimator estimator_;
  std::vector<std::string> joints_;
  std::vector<int> body_index_;
  intent_service::SkeletonFrame frame_;
  collision::JointMixture mixture_;
  std::vector<collision::JointMixture> mixtures_;
  std::vector<bool> done_;
};

// A baseline fed every observed skeleton in order; repeated requests for
// the same frame get the same prediction.
class BaselineSource {
 public:
  BaselineSource(intent::BaselinePredictorParams params, const PersonStream& person)
      : person_(person), predictor_(params, static_cast<int>(person.joint_names.size())) {}

  const collision::JointMixture* At(int frame) {
    while (last_ < frame) {
      ++last_;
      const Eigen::Matrix3Xd& seen = person_.observed[static_cast<std::size_t>(last_)];
      const Eigen::VectorXd p = Eigen::Map<const Eigen::VectorXd>(seen.data(), seen.size());
      predictor_.Update(person_.stamp(last_), p, &mixture_);
      current_ = Stamped(mixture_, person_.joint_names, SimTimeNs(person_.stamp(last_)));
    }
    return last_ == frame ? &current_ : nullptr;
  }

 private:
  const PersonStream& person_;
  intent::BaselinePredictor predictor_;
  collision::JointMixture mixture_;
  collision::JointMixture current_;
  int last_ = -1;
};

// What an oracle knows of the future: from frame `frame` on, the person's
// motion is that of the stream it returns (the person's own for the oracle;
// for oracle-action the person's current action going on for ever).
using FutureOf = std::function<const PersonStream&(int frame)>;

// How the oracles see the future (cell_benchmark.h, CellBenchmarkSetup).
struct OracleOptions {
  FutureOf action_continued;  ///< oracle-action's future; empty: oracle-action cannot run
  /// m per axis at the last step: each forecast's means get an error, drawn
  /// per frame and joint, growing linearly over the steps (0: exact).
  double error_std = 0;
  uint64_t error_seed = 0;
};

// The true future at the model's steps with the model's within-action
// covariances, plus the error of OracleOptions.
class OracleSource {
 public:
  OracleSource(FutureOf future, double error_std, uint64_t error_seed, ModelTrack* model,
               const PersonStream& person, const intent::IntentModel& config)
      : future_(std::move(future)),
        error_std_(error_std),
        error_seed_(error_seed),
        person_(person),
        model_(model),
        dt_(1.0 / config.config.rate),
        steps_(config.config.horizon) {}

  const collision::JointMixture* At(int frame) {
    if (frame == frame_) return &current_;
    if (!model_->At(frame)) return nullptr;
    frame_ = frame;
    const std::size_t J = model_->joints().size();
    current_ = collision::JointMixture{};
    current_.t0_ns = SimTimeNs(person_.stamp(frame));
    current_.time_step = dt_;
    current_.num_steps = steps_;
    current_.joint_names = model_->joints();
    current_.actions = {"oracle"};
    current_.probabilities = {1.0};
    current_.means.assign(1, std::vector<Eigen::Vector3d>(static_cast<std::size_t>(steps_) * J));
    current_.covariances.assign(1, std::vector<Eigen::Matrix3d>(static_cast<std::size_t>(steps_) * J));
    // The error at the last step, per joint: the same draws for a frame
    // whatever the order of the calls.
    error_.assign(J, Eigen::Vector3d::Zero());
    if (error_std_ > 0) {
      std::mt19937_64 g(Mix(error_seed_ ^ Mix(static_cast<uint64_t>(frame))));
      std::normal_distribution<double> n(0.0, error_std_);
      for (auto& e : error_) e = Eigen::Vector3d(n(g), n(g), n(g));
    }
    const PersonStream& future = future_(frame);
    for (int k = 0; k < steps_; ++k) {
      future.TrueAt(person_.stamp(frame) + (k + 1) * dt_, &p_WJ_);
      const double grown = static_cast<double>(k + 1) / steps_;
      for (std::size_t j = 0; j < J; ++j) {
        const std::size_t o = static_cast<std::size_t>(k) * J + j;
        current_.means[0][o] = p_WJ_.col(model_->body_index(j)) + grown * error_[j];
        current_.covariances[0][o] = model_->WithinCovariance(frame, k, j);
      }
    }
    return &current_;
  }

 private:
  FutureOf future_;
  double error_std_;
  uint64_t error_seed_;
  const PersonStream& person_;
  ModelTrack* model_;
  double dt_;
  int steps_;
  int frame_ = -1;
  collision::JointMixture current_;
  std::vector<Eigen::Vector3d> error_;
  Eigen::Matrix3Xd p_WJ_;
};

// What one predictor's run is fed: the planner's prediction source and the
// monitor's (BenchmarkSetup::monitor_input; with none the monitor gets the
// model's, as the cell's intent service still runs). Holds the sources it
// points into: not copyable or movable. Throws std::invalid_argument for
// oracle-action without OracleOptions::action_continued.
class PredictorSources {
 public:
  PredictorSources(const BenchmarkSetup& setup, const PersonStream& person, ModelTrack* track, Predictor p,
                   const OracleOptions& oracle = {}) {
    model_ = [track](int f) { return track->At(f); };
    const intent::IntentModel& model = *setup.intent_model;
    switch (p) {
      case Predictor::kNone:
        break;
      case Predictor::kConstantPosition:
      case Predictor::kConstantVelocity: {
        intent::BaselinePredictorParams bp =
            p == Predictor::kConstantPosition ? setup.constant_position : setup.constant_velocity;
        bp.rate = model.config.rate;
        bp.horizon = model.config.horizon;
        baseline_.emplace(bp, person);
        planner_ = [this](int f) { return baseline_->At(f); };
        break;
      }
      case Predictor::kModel:
        planner_ = model_;
        break;
      case Predictor::kOracle:
      case Predictor::kOracleAction: {
        FutureOf future = [&person](int) -> const PersonStream& { return person; };
        if (p == Predictor::kOracleAction) {
          if (!oracle.action_continued) {
            throw std::invalid_argument("the oracle-action predictor needs the person's actions (iplan eval cell only)");
          }
          future = oracle.action_continued;
        }
        oracle_.emplace(std::move(future), oracle.error_std, oracle.error_seed, track, person, model);
        planner_ = [this](int f) { return oracle_->At(f); };
        break;
      }
    }
    own_ = setup.monitor_input == MonitorInput::kSame && p != Predictor::kNone;
  }
  PredictorSources(const PredictorSources&) = delete;
  PredictorSources& operator=(const PredictorSources&) = delete;

  const PredictionSource& planner() const { return planner_; }
  const PredictionSource& monitor() const { return own_ ? planner_ : model_; }

 private:
  std::optional<BaselineSource> baseline_;
  std::optional<OracleSource> oracle_;
  PredictionSource planner_, model_;
  bool own_ = false;
};

// The true bound's covariances at a frame: the model's first step, in body
// order (the isotropic LoopParams::true_bound_std where the model has none).
class TrueCovariances {
 public:
  TrueCovariances(const BenchmarkSetup& setup, ModelTrack* track)
      : track_(track),
        covs_(setup.models.body->params().joints.size()),
        fallback_(setup.loop.true_bound_std * setup.loop.true_bound_std * Eigen::Matrix3d::Identity()) {
    source_ = [this](int f) -> const std::vector<Eigen::Matrix3d>* {
      if (!track_->At(f)) return nullptr;
      if (f != frame_) {
        std::fill(covs_.begin(), covs_.end(), fallback_);
        for (std::size_t j = 0; j < track_->joints().size(); ++j) {
          covs_[static_cast<std::size_t>(track_->body_index(j))] = track_->WithinCovariance(f, 0, j);
        }
        frame_ = f;
      }
      return &covs_;
    };
  }
  TrueCovariances(const TrueCovariances&) = delete;
  TrueCovariances& operator=(const TrueCovariances&) = delete;
  const CovarianceSource& source() const { return source_; }

 private:
  ModelTrack* track_;
  std::vector<Eigen::Matrix3d> covs_;
  Eigen::Matrix3d fallback_;
  int frame_ = -1;
  CovarianceSource source_;
};

}  // namespace iplan::cell_sim::internal
