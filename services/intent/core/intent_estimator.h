// Online intent estimation for the intent service, without DDS types.
//
// Per tracked body (body id) the estimator keeps the recent skeleton frames,
// resamples them to the model rate on a grid anchored at the newest frame
// (rows at t, t - 1/rate, ..., linear interpolation between neighbouring
// frames), forms the window of the last T rows (padded at the front by the
// library while fewer have been observed) and runs iplan::intent::PredictIntent.
// The action probabilities of successive windows of a body are combined by an
// iplan::intent::BeliefFilter with the model's parameters
// (model.classifier.belief, cross-validated at training time), exactly as in
// iplan::intent::EvaluateIntentModel; the filter restarts with the body's
// history (new body or tracking gap).
//
// Frames: positions are metres in the frame of the incoming skeletons (W);
// the model must have been trained in that frame. Stamps are seconds (any
// epoch, typically Unix time).
//
// Dependencies: this core -> iplan::intent -> Eigen. Not thread-safe (one
// instance per executor thread). Update allocates (the body's frame buffer,
// the window while it is shorter than T, and inside PredictIntent); it is
// not real-time safe.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "iplan/core/name_value.h"
#include "iplan/intent/belief_filter.h"
#include "iplan/intent/coverage_adapter.h"
#include "iplan/intent/intent_model.h"

namespace iplan::intent_service {

/// One observed joint: its name as published and its position p_WJ (m, W).
struct JointObservation {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

/// One skeleton frame of one body.
struct SkeletonFrame {
  std::uint32_t body_id = 0;
  double stamp = 0.0;  ///< s, time of the observation
  std::vector<JointObservation> joints;  ///< any order; extra joints are ignored
};

struct IntentEstimatorParams {
  /// s: a body without frames for this long is forgotten (its buffer dropped).
  double body_timeout = 1.0;
  /// s: a gap between two frames of a body longer than this restarts the
  /// body's history (the window is never interpolated across it), like the
  /// training-time splitting of recordings.
  double max_gap = 0.6;
  /// Bodies tracked at once; frames of further bodies are rejected.
  int max_bodies = 8;
  /// s: online calibration of each body's forecast ellipsoids
  /// (intent::CoverageAdapterParams::halving_time); 0: the model's own.
  double coverage_halving_time = intent::CoverageAdapterParams{}.halving_time;
  /// A new body (or one back from a tracking gap) starts from the ellipsoid
  /// scales last learned in this cell (true) or from the model's (false).
  bool coverage_carry_over = intent::CoverageAdapterParams{}.carry_over;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(body_timeout, "s without a skeleton after which a body is forgotten, > 0"));
    a->Visit(IPLAN_NVP(max_gap, "s; a longer gap between two skeletons of a body restarts its history, > 0"));
    a->Visit(IPLAN_NVP(max_bodies, "bodies tracked at once; skeletons of more are rejected, in [1, 1000]"));
    a->Visit(IPLAN_NVP(coverage_halving_time,
                       "s; each body's forecast ellipsoids follow its own matured forecasts (95 % inside): "
                       "with all inside their variance halves in this time; 0: the model's covariances, >= 0"));
    a->Visit(IPLAN_NVP(coverage_carry_over,
                       "true: a new body's ellipsoids start from the scales last learned in this cell; "
                       "false: from the model's"));
  }
  /// Empty when valid, else the offending field and value.
  std::string Validate() const;
  /// The coverage adapter's parameters these settings give.
  intent::CoverageAdapterParams CoverageParams() const;
};

/// Why a frame was not used. The names (ToString) appear in diagnostics.
enum class FrameStatus {
  kAccepted,
  kMissingJoint,       ///< a model joint is absent or not detected (NaN / exactly 0,0,0)
  kDuplicateJoint,     ///< a model joint appears twice
  kStampNotIncreasing, ///< stamp not after the body's previous frame (or not finite)
  kTooManyBodies,      ///< max_bodies already tracked
};
const char* ToString(FrameStatus status);

struct FrameResult {
  FrameStatus status = FrameStatus::kAccepted;
  std::string reason;  ///< human-readable detail when rejected
  bool accepted() const { return status == FrameStatus::kAccepted; }
};

class IntentEstimator {
 public:
  /// Throws std::invalid_argument when `params` is invalid or `model` is null.
  IntentEstimator(std::shared_ptr<const intent::IntentModel> model, IntentEstimatorParams params);

  /// Adds a frame. When accepted, `*out` holds the mixture prediction for the
  /// window ending at frame.stamp (future step k at stamp + (k + 1) / rate),
  /// its action probabilities being the body's belief over its windows so far,
  /// and bodies unseen for longer than body_timeout before frame.stamp are
  /// dropped. A rejected frame changes nothing.
  FrameResult Update(const SkeletonFrame& frame, collision::JointMixture* out);

  /// Forgets bodies whose newest frame is older than now - body_timeout
  /// (now in the stamps' clock, s). Returns how many were dropped.
  int DropStale(double now);

  int num_bodies() const { return static_cast<int>(bodies_.size()); }
  /// Frames currently buffered for a body (0 when unknown).
  int buffered_frames(std::uint32_t body_id) const;
  const intent::IntentModel& model() const { return *model_; }
  /// Model joints, in output order.
  const std::vector<std::string>& joint_names() const { return model_->config.joints.joints; }

 private:
  struct Body {
    Body(const intent::IntentModel& model, const intent::CoverageAdapterParams& coverage_params)
        : belief(static_cast<int>(model.actions.size()), model.classifier.belief),
          coverage(static_cast<int>(model.config.joints.joints.size()), model.config.horizon, model.config.rate,
                   coverage_params) {}
    std::deque<double> stamps;             // s, increasing
    std::deque<Eigen::VectorXd> positions; // (3 J) per frame, model joint order
    intent::BeliefFilter belief;           // over this body's windows since its history began
    intent::CoverageAdapter coverage;      // this body's ellipsoid scales, restarted with the belief
  };
  /// Fills window_ from a body's history; returns the number of rows.
  void BuildWindow(const Body& body);

  std::shared_ptr<const intent::IntentModel> model_;
  IntentEstimatorParams params_;
  std::unordered_map<std::string, int> joint_index_;  // model joint name -> index
  std::map<std::uint32_t, Body> bodies_;
  double span_ = 0.0;           // s of history a window needs: (T - 1) / rate
  Eigen::VectorXd scratch_;     // (3 J) positions of the incoming frame
  std::vector<int> seen_;       // per model joint: times seen in the frame
  Eigen::MatrixXd window_;      // (<= T, 3 J)
  Eigen::VectorXd window_probabilities_;  // (C) of the newest window
  // (J) where a new body's ellipsoid scales start: the scales last learned
  // with coverage_carry_over, else always 1 (the model's).
  Eigen::VectorXd cell_scales_;
};

}  // namespace iplan::intent_service
