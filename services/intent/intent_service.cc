// iplan-intent: for every accepted human skeleton, publishes the action
// belief p(action | motion) and the predicted future motion (a Gaussian
// mixture over actions) computed by the intent model (common/intent) through
// the online estimator in core/. Positions stay in the skeleton's frame
// (header.frame_id), which must be the frame the model was trained in.
// `intent.predictor` chooses what is published as the prediction: the
// model's mixture (default), or a kinematic baseline (constant position or
// constant velocity, iplan/intent/baseline_predictors.h) of the model's
// joints at the model's rate and horizon, for measuring what the model adds;
// the action belief always comes from the model.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>

#include "services/intent/core/intent_estimator.h"
#include "services/intent/core/intent_settings.h"
#include "iplan/adapters/adapters.h"
#include "iplan/core/params.h"
#include "iplan/framework/service.h"
#include "iplan/intent/baseline_predictors.h"
#include "iplan/intent/model_io.h"

namespace iplan::intent_service {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class IntentService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    IntentSettings settings;
    core::ReadParams(config, &settings);  // every range: IntentSettings::Validate
    if (const std::string why = settings.Validate(); !why.empty()) return Result::Fail(why);
    params_ = settings.estimator;
    predictor_ = settings.predictor;
    settings.baseline.ApplyTo(&baseline_);
    baseline_covariance_ = settings.baseline.covariance;
    const std::vector<std::string>& joints = settings.joints;
    const double rate = settings.rate_hz;

    const std::string path = config.ResolvePath(settings.model);
    intent::ModelExpectation expected;
    expected.joints = joints;
    expected.rate = rate;
    try {
      model_ = std::make_shared<const intent::IntentModel>(intent::LoadIntentModel(path, expected));
      estimator_ = std::make_unique<IntentEstimator>(model_, params_);
    } catch (const std::exception& e) {
      return Result::Fail(config.file() + ": key 'intent.model': " + e.what());
    }
    node.log().info("model {}: {} actions, {} joints, {} Hz, window {} frames, horizon {} steps; predictions from {}", path,
                    model_->actions.size(), joints.size(), rate, model_->config.window, model_->config.horizon,
                    predictor_);
    baseline_.kind = predictor_ == "constant-position" ? intent::BaselineKind::kConstantPosition
                                                       : intent::BaselineKind::kConstantVelocity;
    baseline_.rate = model_->config.rate;
    baseline_.horizon = model_->config.horizon;
    if (const std::string why = baseline_.Validate(); !why.empty()) {
      return Result::Fail(config.file() + ": key 'intent.baseline': " + why);
    }

    belief_writer_ = &node.Advertise(framework::topics::ActionBelief());
    prediction_writer_ = &node.Advertise(framework::topics::HumanPrediction());
    node.Subscribe(framework::topics::HumanSkeleton(),
                   std::function<void(const msg::HumanSkeleton&, const dds::SampleInfo&)>(
                       [this, &node](const msg::HumanSkeleton& s, const dds::SampleInfo&) { OnSkeleton(node, s); }));
    // Static parts of the outputs.
    belief_.actions = model_->actions;
    prediction_.time_step = 1.0 / model_->config.rate;
    prediction_.num_steps = static_cast<uint32_t>(model_->config.horizon);
    prediction_.joint_names = model_->config.joints.joints;
    node.SetDiagnosticValue("model", path);
    node.SetDiagnosticValue("predictor", predictor_);
    UpdateDiagnostics(node);
    return Result::Ok();
  }

  Result OnActivate(Node& node) override {
    // Bodies that stop being published are forgotten even if no other body
    // keeps the estimator busy.
    const auto period = std::chrono::duration<double>(params_.body_timeout / 2);
    timer_ = node.AddTimer(std::chrono::duration_cast<std::chrono::nanoseconds>(period), [this, &node] {
      // The counts between the every-30th-frame updates reach the
      // diagnostics here too (at most body_timeout / 2 late).
      estimator_->DropStale(msg::ToSeconds(msg::Now()));
      UpdateDiagnostics(node);
      // Baselines of bodies not seen for body_timeout go with them.
      const double now = msg::ToSeconds(msg::Now());
      for (auto b = last_baseline_stamp_.begin(); b != last_baseline_stamp_.end();) {
        if (now - b->second > params_.body_timeout) {
          baselines_.erase(b->first);
          b = last_baseline_stamp_.erase(b);
        } else {
          ++b;
        }
      }
    });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    node.CancelTimer(timer_);
    return Result::Ok();
  }

  Result OnCleanup(Node&) override {
    estimator_.reset();
    model_.reset();
    return Result::Ok();
  }

 private:
  void OnSkeleton(Node& node, const msg::HumanSkeleton& s) {
    const auto start = std::chrono::steady_clock::now();
    frame_.body_id = s.body_id;
    frame_.stamp = msg::ToSeconds(s.header.stamp);
    frame_.joints.resize(s.joints.size());
    for (std::size_t j = 0; j < s.joints.size(); ++j) {
      frame_.joints[j].name = s.joints[j].name;
      frame_.joints[j].position = {s.joints[j].position.x, s.joints[j].position.y, s.joints[j].position.z};
    }
    const FrameResult r = estimator_->Update(frame_, &mixture_);
    if (r.accepted() && predictor_ != "model") PredictBaseline(s);
    if (!r.accepted()) {
      const std::string kind = ToString(r.status);
      const uint64_t n = ++rejected_[kind];
      ++rejected_total_;
      if (n == 1) node.log().warn("skeleton of body {} rejected ({}): {}; further '{}' rejections are only counted",
                                  s.body_id, kind, r.reason, kind);
      node.SetDiagnosticValue("last_rejected_frame", r.reason);
      UpdateDiagnostics(node);
      return;
    }
    ++accepted_;
    Publish(node, s);
    if (accepted_ % 30 == 1) UpdateDiagnostics(node);
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }

  // The baseline's prediction replaces the model's (the belief stays the
  // model's). One predictor per body, forgotten with the estimator's bodies.
  void PredictBaseline(const msg::HumanSkeleton& s) {
    const auto& joints = model_->config.joints.joints;
    Eigen::VectorXd p(3 * static_cast<Eigen::Index>(joints.size()));
    for (std::size_t j = 0; j < joints.size(); ++j) {
      // The estimator accepted the frame: every model joint is present.
      const auto it = std::find_if(s.joints.begin(), s.joints.end(), [&](const msg::HumanJoint& h) { return h.name == joints[j]; });
      const auto& q = it->position;
      p.segment<3>(3 * static_cast<Eigen::Index>(j)) << q.x, q.y, q.z;
    }
    auto it = baselines_.find(s.body_id);
    if (it == baselines_.end()) {
      it = baselines_.emplace(s.body_id, intent::BaselinePredictor(baseline_, static_cast<int>(joints.size()))).first;
    }
    const double stamp = msg::ToSeconds(s.header.stamp);
    if (it->second.buffered_frames() > 0 && !(stamp > last_baseline_stamp_[s.body_id])) it->second.Reset();
    last_baseline_stamp_[s.body_id] = stamp;
    it->second.Update(stamp, p, &baseline_mixture_);
    if (baseline_covariance_ == "model") {
      // The model's uncertainty around the baseline's mean: per step and
      // joint the probability-weighted covariance of the model's components
      // (without the spread of their means), so a comparison with the model
      // differs in the mean forecast only.
      std::vector<Eigen::Matrix3d>& g = baseline_mixture_.covariances.at(0);
      for (std::size_t k = 0; k < g.size(); ++k) {
        Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
        for (std::size_t a = 0; a < mixture_.probabilities.size(); ++a) {
          c += mixture_.probabilities[a] * mixture_.covariances[a].at(k);
        }
        g[k] = c;
      }
    }
  }

  void Publish(Node& node, const msg::HumanSkeleton& s) {
    // Our own stamp on our outputs (a consumer orders them by it); the
    // skeleton's stamp, t0 of the prediction steps, travels beside it.
    const msg::Time now = msg::Now();
    belief_.header.stamp = now;
    belief_.header.frame_id = s.header.frame_id;
    belief_.observation_stamp = s.header.stamp;
    belief_.body_id = s.body_id;
        prediction_.header.stamp = now;
    prediction_.header.frame_id = s.header.frame_id;
    prediction_.observation_stamp = s.header.stamp;
    prediction_.body_id = s.body_id;
    belief_.probabilities = mixture_.probabilities;
    services::FillPrediction(predictor_ == "model" ? mixture_ : baseline_mixture_, &prediction_);
    std::string err;
    if (!belief_writer_->Write(belief_, &err) && !warned_write_) {
      node.log().error("action belief not published: {}", err);
      warned_write_ = true;
    }
    if (!prediction_writer_->Write(prediction_, &err) && !warned_write_) {
      node.log().error("prediction not published: {}", err);
      warned_write_ = true;
    }
  }

  void UpdateDiagnostics(Node& node) {
    node.SetDiagnosticValue("frames_accepted", std::to_string(accepted_));
    node.SetDiagnosticValue("frames_rejected", std::to_string(rejected_total_));
    for (const auto& [kind, n] : rejected_) node.SetDiagnosticValue("frames_rejected/" + kind, std::to_string(n));
    node.SetDiagnosticValue("bodies", std::to_string(estimator_->num_bodies()));
  }

  IntentEstimatorParams params_;
  std::shared_ptr<const intent::IntentModel> model_;
  std::unique_ptr<IntentEstimator> estimator_;
  dds::Writer<msg::ActionBelief>* belief_writer_ = nullptr;
  dds::Writer<msg::HumanPrediction>* prediction_writer_ = nullptr;
  SkeletonFrame frame_;               // reused
  collision::JointMixture mixture_;   // reused
  std::string predictor_ = "model";  // model, constant-position, constant-velocity
  intent::BaselinePredictorParams baseline_;
  std::string baseline_covariance_ = "model";  // model: the model's covariances; growth: the baseline's own
  std::map<std::uint32_t, intent::BaselinePredictor> baselines_;
  std::map<std::uint32_t, double> last_baseline_stamp_;  // s, newest frame per body
  collision::JointMixture baseline_mixture_;  // reused
  msg::ActionBelief belief_;          // reused
  msg::HumanPrediction prediction_;   // reused
  std::map<std::string, uint64_t> rejected_;
  uint64_t rejected_total_ = 0;
  uint64_t accepted_ = 0;
  bool warned_write_ = false;
  int timer_ = 0;
};

}  // namespace
}  // namespace iplan::intent_service

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv,
      {"intent", "publishes the action belief and the predicted human motion for every tracked skeleton"},
      [] { return std::make_unique<iplan::intent_service::IntentService>(); });
}
