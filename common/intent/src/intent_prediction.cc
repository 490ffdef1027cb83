// Prediction, METHOD.md sections 2-3: the action probabilities of one window
// (DTW kernel against the import windows, IVM) and the Gaussian mixture over
// actions of the per-action forecasts (docs/intent.md, pipeline step 6).
#include <cmath>
#include <stdexcept>
#include <string>

#include "intent_training.h"
#include "iplan/intent/dtw.h"

namespace iplan::intent {
namespace {

// Pads/trims a window to the model's T rows and checks it.
Eigen::MatrixXd NormaliseWindow(const IntentModel& model, const Eigen::MatrixXd& window) {
  const int J = static_cast<int>(model.config.joints.joints.size());
  if (window.rows() < 1 || window.cols() != 3 * J) {
    throw std::invalid_argument("intent window has " + std::to_string(window.rows()) +
                                " x " + std::to_string(window.cols()) +
                                " entries; expected >= 1 rows and " +
                                std::to_string(3 * J) + " columns (3 x joints)");
  }
  if (!window.allFinite()) throw std::invalid_argument("intent window has non-finite values");
  return WindowEndingAt(window, static_cast<int>(window.rows()) - 1, model.config.window);
}

Eigen::VectorXd ClassifyPadded(const IntentModel& model, const FeatureLayout& layout,
                               const Eigen::MatrixXd& padded) {
  const Eigen::MatrixXd f = layout.FrameFeatures(padded).transpose();
  const ActionClassifier& cl = model.classifier;
  const Eigen::Index q = static_cast<Eigen::Index>(cl.import_windows.size());
  Eigen::VectorXd k(q);
  std::vector<double> ws;
  for (Eigen::Index s = 0; s < q; ++s) {
    const double d = DtwDistanceColumns(f, cl.import_windows[s], model.config.dtw_band, &ws);
    k(s) = DtwKernel(d, cl.sigma);
  }
  Eigen::VectorXd p;
  cl.ivm.Probabilities(k, &p);
  return p;
}

}  // namespace

namespace detail {

// rho_j^2 of ForecastSettings for window speeds `u` (J).
double ActivityFactor(const ForecastSettings& f, const Eigen::VectorXd& u, int j) {
  if (!std::isfinite(f.motion_offset)) return 1.0;
  const double rho = (u(j) + f.motion_offset) / (f.reference_speed(j) + f.motion_offset);
  return rho * rho;
}

// Predicted residual (P, m) and its variance (P, m^2, without sensor noise)
// for the unstandardised input `x`.
void PredictResidual(const ActionForecaster& fc, const Eigen::VectorXd& x, Eigen::VectorXd* mean,
                     Eigen::VectorXd* var) {
  const Eigen::VectorXd xs = (x - fc.input_mean).cwiseQuotient(fc.input_scale);
  double v = 0.0;
  fc.gp.Predict(xs, mean, &v);
  *mean = fc.output_mean + fc.output_scale.cwiseProduct(*mean);
  *var = v * fc.output_scale.cwiseAbs2();
}

}  // namespace detail

Eigen::VectorXd ClassifyWindow(const IntentModel& model, const Eigen::MatrixXd& window) {
  const FeatureLayout layout(model.config.joints, model.config.features);
  return ClassifyPadded(model, layout, NormaliseWindow(model, window));
}

void PredictIntent(const IntentModel& model, const Eigen::MatrixXd& window,
                   JointMixture* out) {
  const FeatureLayout layout(model.config.joints, model.config.features);
  const Eigen::MatrixXd padded = NormaliseWindow(model, window);
  const Eigen::VectorXd p = ClassifyPadded(model, layout, padded);
  const int C = static_cast<int>(model.actions.size());
  const int J = layout.num_joints();
  const int H = model.config.horizon;
  out->time_step = 1.0 / model.config.rate;
  out->joint_names = model.config.joints.joints;
  out->Resize(C, H, J);
  const Eigen::VectorXd x = layout.ForecastInput(padded, model.config.rate, model.config.velocity_frames,
                                                 model.config.history_samples);
  Eigen::MatrixXd base;
  ExtrapolateKinematic(padded, model.forecast.baseline, model.config.rate, H, &base);
  const double noise = model.config.sensor_noise_std * model.config.sensor_noise_std;
  const double w = model.forecast.residual_weight;
  const Eigen::VectorXd& scale = model.forecast.variance_scale;
  Eigen::VectorXd mean, var, speeds;
  if (std::isfinite(model.forecast.motion_offset)) MeanJointSpeeds(padded, model.config.rate, &speeds);
  for (int c = 0; c < C; ++c) {
    out->actions[c] = model.actions[c];
    out->probabilities[c] = p(c);
    detail::PredictResidual(model.forecasters[c], x, &mean, &var);
    for (int k = 0; k < H; ++k) {
      for (int j = 0; j < J; ++j) {
        const size_t i = static_cast<size_t>(k) * J + j;
        Eigen::Vector3d& mu = out->means[c][i];
        Eigen::Matrix3d& sigma = out->covariances[c][i];
        const int o = (k * J + j) * 3;
        const double s = (scale.size() == 0 ? 1.0 : scale(k * J + j)) *
                         detail::ActivityFactor(model.forecast, speeds, j);
        sigma.setZero();
        for (int a = 0; a < 3; ++a) {
          mu(a) = base(k, 3 * j + a) + w * mean(o + a);
          sigma(a, a) = s * (var(o + a) + noise);
        }
      }
    }
  }
}

}  // namespace iplan::intent
