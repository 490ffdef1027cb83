// Training of the per-action forecasters, METHOD.md section 3: one sparse
// pseudo-input GP (SPGP/FITC) per action on the residual of the future about
// a kinematic extrapolation, and the ForecastSettings chosen on the training
// data only: the extrapolation (L, tau), the residual weight w and the
// covariance calibration (s_kj, m0) by cross-validation (docs/intent.md,
// pipeline step 5).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "intent_training.h"
#include "iplan/intent/forecast_calibration.h"
#include "iplan/intent/model_selection.h"

namespace iplan::intent::detail {
namespace {

constexpr double kTwoPi = 6.283185307179586;
// Bounds of the calibrated covariance scale s: at least a tenth of the
// uncalibrated standard deviation is kept, e.g. for a joint that never moved
// in the training data (assembly.csv's shoulders are constant).
constexpr double kMinVarianceScale = 1e-2;
constexpr double kMaxVarianceScale = 1e4;

// The q-quantile (q in [0, 1]) of `v` by linear interpolation; `v` non-empty.
double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

// A forecaster training window: the one ending at row `end` of `track`.
struct ForecastSample {
  const Track* track;
  int end;
  int fold;  // forecaster cross-validation fold
};

// The recorded future (horizon, 3 J) after `end`; past the end of the track
// the last pose is held (short clips, TrainParams::min_forecast_windows).
Eigen::MatrixXd Future(const Track& t, int end, int horizon) {
  const int n = static_cast<int>(t.positions.rows());
  Eigen::MatrixXd f(horizon, t.positions.cols());
  for (int k = 0; k < horizon; ++k) f.row(k) = t.positions.row(std::min(end + k + 1, n - 1));
  return f;
}

// SPGP inputs X (N, D_in) and residual targets Y (N, horizon * 3 J) of the
// samples about the kinematic extrapolation `baseline`.
void ForecastData(const std::vector<ForecastSample>& samples, const FeatureLayout& layout,
                  const IntentModelConfig& config, const KinematicBaseline& baseline,
                  Eigen::MatrixXd* X, Eigen::MatrixXd* Y, Eigen::MatrixXd* speeds = nullptr) {
  const int N = static_cast<int>(samples.size());
  const int J = layout.num_joints();
  const int H = config.horizon;
  X->resize(N, layout.forecast_input_size(config.history_samples));
  Y->resize(N, H * 3 * J);
  if (speeds != nullptr) speeds->resize(N, J);
  Eigen::MatrixXd base;
  Eigen::VectorXd u;
  for (int i = 0; i < N; ++i) {
    const Track& t = *samples[i].track;
    const Eigen::MatrixXd window = WindowEndingAt(t.positions, samples[i].end, config.window);
    X->row(i) = layout.ForecastInput(window, config.rate, config.velocity_frames, config.history_samples).transpose();
    ExtrapolateKinematic(window, baseline, config.rate, H, &base);
    const Eigen::MatrixXd future = Future(t, samples[i].end, H);
    for (int k = 0; k < H; ++k) Y->block(i, k * 3 * J, 1, 3 * J) = future.row(k) - base.row(k);
    if (speeds != nullptr) {
      MeanJointSpeeds(window, config.rate, &u);
      speeds->row(i) = u.transpose();
    }
  }
}

// Standardises X and Y and fits the SPGP of one action.
ActionForecaster FitForecaster(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                               const TrainParams& params, std::uint64_t seed) {
  const Eigen::Index Ns = X.rows();
  ActionForecaster fc;
  fc.input_mean = X.colwise().mean().transpose();
  fc.input_scale = ((X.rowwise() - fc.input_mean.transpose()).colwise().squaredNorm() / Ns)
                       .cwiseSqrt().transpose();
  // One scale for every output (their overall standard deviation): the
  // outputs share the SPGP's hyperparameters, and in common units the
  // likelihood is fitted to the joints and steps that move most, not
  // equally to the still ones, whose residual is sensor noise.
  fc.output_mean = Y.colwise().mean().transpose();
  const double spread = std::sqrt((Y.rowwise() - fc.output_mean.transpose()).squaredNorm() /
                                  static_cast<double>(Ns * Y.cols()));
  fc.output_scale = Eigen::VectorXd::Constant(Y.cols(), std::max(spread, 1e-9));
  for (Eigen::Index d = 0; d < fc.input_scale.size(); ++d) {
    if (!(fc.input_scale(d) > 1e-9)) fc.input_scale(d) = 1.0;
  }
  const Eigen::MatrixXd Xs = (X.rowwise() - fc.input_mean.transpose()) *
                             fc.input_scale.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd Ys = (Y.rowwise() - fc.output_mean.transpose()) *
                             fc.output_scale.cwiseInverse().asDiagonal();
  SparseGpParams gp;
  gp.num_pseudo_inputs = params.pseudo_inputs;
  gp.max_iterations = params.gp_iterations;
  gp.seed = seed;
  fc.gp = SparseGp::Fit(Xs, Ys, gp);
  fc.num_training_windows = static_cast<int>(Ns);
  return fc;
}

// Chooses the motion offset m0 and the per-(step, joint) variance scales on
// the held-out residuals (true r_true, predicted r_pred with variances r_var,
// window speeds r_speed) at the chosen residual weight; fills the report.
void CalibrateForecast(const std::vector<Eigen::RowVectorXd>& r_true,
                       const std::vector<Eigen::RowVectorXd>& r_pred,
                       const std::vector<Eigen::RowVectorXd>& r_var,
                       const std::vector<Eigen::RowVectorXd>& r_speed, const IntentModelConfig& config,
                       const TrainParams& params, ForecastSettings* f, TrainReport* rep) {
  const int H = config.horizon;
  const int J = static_cast<int>(config.joints.joints.size());
  const Eigen::Index N = static_cast<Eigen::Index>(r_true.size());
  const double w = f->residual_weight;
  const double noise = config.sensor_noise_std * config.sensor_noise_std;
  Eigen::MatrixXd err(N, 3), var(N, 3);
  Eigen::VectorXd scales(static_cast<Eigen::Index>(H) * J);
  double best_nll = std::numeric_limits<double>::infinity();
  for (double m0 : params.motion_offsets) {
    ForecastSettings trial = *f;
    trial.motion_offset = m0;
    double nll = 0.0, raw = 0.0, calibrated = 0.0;
    for (int k = 0; k < H; ++k) {
      for (int j = 0; j < J; ++j) {
        const int o = (k * J + j) * 3;
        for (Eigen::Index i = 0; i < N; ++i) {
          err.row(i) = r_true[i].segment<3>(o) - w * r_pred[i].segment<3>(o);
          var.row(i) = ActivityFactor(trial, r_speed[i].transpose(), j) *
                       (r_var[i].segment<3>(o).array() + noise).matrix();
        }
        raw += EllipsoidCoverage(err, var, 0.0, 1.0);
        const double s = CalibrateVarianceScale(err, var, 0.0, 0.95, kMinVarianceScale, kMaxVarianceScale);
        scales(static_cast<Eigen::Index>(k) * J + j) = s;
        calibrated += EllipsoidCoverage(err, var, 0.0, s);
        const Eigen::ArrayXXd total = s * var.array();
        nll += 0.5 * ((kTwoPi * total).log() + err.array().square() / total).sum() / static_cast<double>(N);
      }
    }
    nll /= static_cast<double>(H) * J;
    rep->motion_cv_table.push_back({m0, nll, calibrated / (H * J)});
    if (nll < best_nll) {
      best_nll = nll;
      f->motion_offset = m0;
      f->variance_scale = scales;
      rep->cv_coverage_raw = raw / (H * J);
      rep->cv_coverage_calibrated = calibrated / (H * J);
    }
  }
  if (!std::isfinite(f->motion_offset)) f->reference_speed.resize(0);
  rep->motion_offset = f->motion_offset;
  std::vector<double> sv(f->variance_scale.data(), f->variance_scale.data() + f->variance_scale.size());
  rep->variance_scale_min = *std::min_element(sv.begin(), sv.end());
  rep->variance_scale_max = *std::max_element(sv.begin(), sv.end());
  rep->variance_scale_median = Quantile(sv, 0.5);
}

// The per-fold mean joint error (options, folds; NaN where a fold has no
// window) of holding the last pose (option 0) and of every (L, tau) of the
// grids (option 1 + l * taus + t), over all samples.
Eigen::MatrixXd BaselineFoldErrors(const std::vector<std::vector<ForecastSample>>& samples,
                                   const std::vector<int>& frames, const std::vector<double>& taus,
                                   int num_folds, const IntentModelConfig& config) {
  const int H = config.horizon;
  const int J = static_cast<int>(config.joints.joints.size());
  const int nt = static_cast<int>(taus.size());
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(1 + frames.size() * taus.size(), std::max(1, num_folds));
  Eigen::VectorXd count = Eigen::VectorXd::Zero(sum.cols());
  Eigen::VectorXd g(H), p, v;
  for (const std::vector<ForecastSample>& action : samples) {
    for (const ForecastSample& smp : action) {
      const int f = std::min(smp.fold, static_cast<int>(sum.cols()) - 1);
      const Eigen::MatrixXd window = WindowEndingAt(smp.track->positions, smp.end, config.window);
      const Eigen::MatrixXd future = Future(*smp.track, smp.end, H);
      for (int k = 0; k < H; ++k) {
        for (int j = 0; j < J; ++j) {
          sum(0, f) += (future.block<1, 3>(k, 3 * j) - window.block<1, 3>(window.rows() - 1, 3 * j)).norm();
        }
      }
      for (size_t l = 0; l < frames.size(); ++l) {
        FitLine(window, frames[l], config.rate, &p, &v);
        for (int ti = 0; ti < nt; ++ti) {
          for (int k = 0; k < H; ++k) g(k) = DampedDisplacement((k + 1) / config.rate, taus[ti]);
          double e = 0.0;
          for (int k = 0; k < H; ++k) {
            for (int j = 0; j < J; ++j) {
              e += (future.row(k).segment<3>(3 * j).transpose() - p.segment<3>(3 * j) - g(k) * v.segment<3>(3 * j))
                       .norm();
            }
          }
          sum(1 + static_cast<Eigen::Index>(l) * nt + ti, f) += e;
        }
      }
      count(f) += static_cast<double>(H) * J;
    }
  }
  for (Eigen::Index f = 0; f < sum.cols(); ++f) {
    sum.col(f) /= count(f) > 0 ? count(f) : std::numeric_limits<double>::quiet_NaN();
  }
  return sum;
}

// The (L, tau) of the grids for the extrapolation alone (nothing is fitted):
// the lowest mean joint error over all samples, unless holding the last pose
// is within one standard error of it across the folds (then L = 1); fills
// the report's table.
KinematicBaseline ChooseBaseline(const std::vector<std::vector<ForecastSample>>& samples, int num_folds,
                                 const IntentModelConfig& config, const TrainParams& params,
                                 TrainReport* rep) {
  std::vector<int> frames;
  for (int L : params.baseline_smoothing_frames) {
    if (L <= config.window) frames.push_back(L);
  }
  if (frames.empty()) frames.push_back(1);
  const std::vector<double>& taus = params.baseline_damping_time_constants;
  const Eigen::MatrixXd fold_error = BaselineFoldErrors(samples, frames, taus, num_folds, config);
  // Overall means (every window weighs the same).
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(fold_error.cols());
  for (const auto& action : samples) {
    for (const ForecastSample& smp : action) weight(std::min<Eigen::Index>(smp.fold, weight.size() - 1)) += 1.0;
  }
  const Eigen::VectorXd error = fold_error.unaryExpr([](double x) { return std::isfinite(x) ? x : 0.0; }) * weight /
                                std::max(1.0, weight.sum());
  rep->error_const_position = error(0);
  const int nt = static_cast<int>(taus.size());
  for (size_t l = 0; l < frames.size(); ++l) {
    for (int ti = 0; ti < nt; ++ti) {
      rep->baseline_table.push_back({static_cast<double>(frames[l]), taus[ti], error(1 + l * nt + ti)});
    }
  }
  Eigen::Index best = 0;
  error.tail(error.size() - 1).minCoeff(&best);
  ++best;
  Eigen::MatrixXd two(2, fold_error.cols());
  two << fold_error.row(0), fold_error.row(best);
  KinematicBaseline b;
  if (SimplestWithinOneStandardError(two) == 1) {
    b.smoothing_frames = frames[(best - 1) / nt];
    // L = 1 has no velocity: any tau is the same; store 0.
    b.damping_time_constant = b.smoothing_frames == 1 ? 0.0 : taus[(best - 1) % nt];
  }
  rep->baseline = b;
  return b;
}

// The forecaster training windows of every action (every forecast_stride-th
// frame of its tracks, the held-last-pose ones only for short clips; a seeded
// random subset of max_forecast_windows) and their cross-validation folds:
// subjects, or the sequences of a single subject, round-robin. Sets
// *num_folds and the window counts of the report.
std::vector<std::vector<ForecastSample>> MakeForecastSamples(const TrainingGroups& g,
                                                             const IntentModelConfig& config,
                                                             const TrainParams& params,
                                                             const std::vector<std::string>& actions,
                                                             int* num_folds, TrainReport* rep) {
  const int C = g.num_actions;
  const int H = config.horizon;
  const int num_subjects = g.num_subjects;
  std::mt19937_64 rng(params.seed);
  // CV folds: subjects, or the sequences of a single subject, round-robin.
  std::map<std::string, int> group_id;
  for (const Track& t : g.tracks) {
    group_id.emplace(num_subjects >= 2 ? t.subject : t.sequence_id, static_cast<int>(group_id.size()));
  }
  *num_folds = std::min(static_cast<int>(group_id.size()), params.forecast_cv_folds);
  std::vector<std::vector<ForecastSample>> samples(C);
  for (int c = 0; c < C; ++c) {
    std::vector<ForecastSample> full, padded;
    for (const Track& t : g.tracks) {
      const int n = static_cast<int>(t.positions.rows());
      const int fold = group_id.at(num_subjects >= 2 ? t.subject : t.sequence_id) % std::max(1, *num_folds);
      for (int e = 0; e < n; e += params.forecast_stride) {
        if (g.action_id.at(ActionAt(t, e)) != c) continue;  // the action being done at the window's end
        (e + H <= n - 1 ? full : padded).push_back({&t, e, fold});
      }
    }
    const bool use_padded = static_cast<int>(full.size()) < params.min_forecast_windows;
    samples[c] = full;
    if (use_padded) samples[c].insert(samples[c].end(), padded.begin(), padded.end());
    if (samples[c].size() < 2) {
      throw std::invalid_argument("TrainIntentModel: action '" + actions[c] +
                                  "' has fewer than two forecaster windows");
    }
    if (static_cast<int>(samples[c].size()) > params.max_forecast_windows) {
      std::shuffle(samples[c].begin(), samples[c].end(), rng);
      samples[c].resize(params.max_forecast_windows);
    }
    rep->forecast_windows.push_back(static_cast<int>(samples[c].size()));
    rep->forecast_padded.push_back(use_padded);
  }
  return samples;
}

// ubar_j: mean window speed of each joint over all forecaster windows.
Eigen::VectorXd ReferenceSpeeds(const std::vector<std::vector<ForecastSample>>& samples,
                                const IntentModelConfig& config, int J) {
  Eigen::VectorXd u, sum = Eigen::VectorXd::Zero(J);
  long count = 0;
  for (const std::vector<ForecastSample>& action : samples) {
    for (const ForecastSample& smp : action) {
      MeanJointSpeeds(WindowEndingAt(smp.track->positions, smp.end, config.window), config.rate, &u);
      sum += u;
      ++count;
    }
  }
  return sum / static_cast<double>(std::max<long>(1, count));
}

// Cross-validated residual predictions: held-out true residuals, predicted
// residual means and variances (m, m^2), one row per held-out window, and
// the window speeds.
struct HeldOutResiduals {
  std::vector<Eigen::RowVectorXd> r_true, r_pred, r_var, r_speed;
  std::vector<int> fold;
};

// Per action and fold an SPGP fitted without the fold predicts it.
HeldOutResiduals CrossValidateResiduals(const std::vector<std::vector<ForecastSample>>& samples,
                                        int num_folds, const FeatureLayout& layout,
                                        const IntentModelConfig& config, const TrainParams& params,
                                        const KinematicBaseline& baseline) {
  HeldOutResiduals h;
  Eigen::VectorXd mean, var;
  for (int c = 0; c < static_cast<int>(samples.size()); ++c) {
    for (int f = 0; f < num_folds; ++f) {
      std::vector<ForecastSample> train, test;
      for (const ForecastSample& smp : samples[c]) (smp.fold == f ? test : train).push_back(smp);
      if (test.empty() || train.size() < 2) continue;
      Eigen::MatrixXd X, Y, Xt, Yt, Ut;
      ForecastData(train, layout, config, baseline, &X, &Y);
      ForecastData(test, layout, config, baseline, &Xt, &Yt, &Ut);
      const ActionForecaster fc =
          FitForecaster(X, Y, params, params.seed + static_cast<std::uint64_t>(c));
      for (Eigen::Index i = 0; i < Xt.rows(); ++i) {
        PredictResidual(fc, Xt.row(i).transpose(), &mean, &var);
        h.r_true.push_back(Yt.row(i));
        h.r_pred.push_back(mean.transpose());
        h.r_var.push_back(var.transpose());
        h.r_speed.push_back(Ut.row(i));
        h.fold.push_back(f);
      }
    }
  }
  return h;
}

// The residual weight: of the grid's weights whose held-out mean joint error
// over all steps is within one standard error (across the folds) of the
// lowest, the smallest; fills the report's table. `h` is not empty.
double ChooseResidualWeight(const HeldOutResiduals& h, const IntentModelConfig& config,
                            const TrainParams& params, int num_folds, int J, TrainReport* rep) {
  const int H = config.horizon;
  const Eigen::Index Nh = static_cast<Eigen::Index>(h.r_true.size());
  const int k_half = std::clamp(static_cast<int>(std::lround(0.5 * config.rate)) - 1, 0, H - 1);
  std::vector<double> weights = params.residual_weights;
  std::sort(weights.begin(), weights.end());
  Eigen::MatrixXd fold_error = Eigen::MatrixXd::Zero(weights.size(), num_folds);
  Eigen::VectorXd fold_count = Eigen::VectorXd::Zero(num_folds);
  for (int f : h.fold) fold_count(f) += static_cast<double>(H) * J;
  for (size_t wi = 0; wi < weights.size(); ++wi) {
    const double w = weights[wi];
    Eigen::VectorXd per_step = Eigen::VectorXd::Zero(H);
    for (Eigen::Index i = 0; i < Nh; ++i) {
      for (int k = 0; k < H; ++k) {
        for (int j = 0; j < J; ++j) {
          const int o = (k * J + j) * 3;
          const double e = (h.r_true[i].segment<3>(o) - w * h.r_pred[i].segment<3>(o)).norm();
          per_step(k) += e;
          fold_error(static_cast<Eigen::Index>(wi), h.fold[i]) += e;
        }
      }
    }
    per_step /= static_cast<double>(Nh * J);
    rep->residual_cv_table.push_back({w, per_step(k_half), per_step(H - 1), per_step.mean()});
  }
  for (int f = 0; f < num_folds; ++f) {
    fold_error.col(f) /= fold_count(f) > 0 ? fold_count(f) : std::numeric_limits<double>::quiet_NaN();
  }
  return weights[SimplestWithinOneStandardError(fold_error)];
}

}  // namespace

void TrainForecasters(const TrainingGroups& groups, const FeatureLayout& layout,
                      const IntentModelConfig& config, const TrainParams& params,
                      IntentModel* model, TrainReport* rep) {
  // ---- Forecasters, one per action (see ForecastSettings). ----
  const int C = groups.num_actions;
  const int J = layout.num_joints();
  int num_folds = 0;
  const std::vector<std::vector<ForecastSample>> samples =
      MakeForecastSamples(groups, config, params, model->actions, &num_folds, rep);
  model->forecast.baseline = ChooseBaseline(samples, num_folds, config, params, rep);
  model->forecast.reference_speed = ReferenceSpeeds(samples, config, J);

  model->forecast.residual_weight = 1.0;
  rep->forecast_cv_folds = num_folds >= 2 ? num_folds : 0;
  if (num_folds >= 2) {
    const HeldOutResiduals h =
        CrossValidateResiduals(samples, num_folds, layout, config, params, model->forecast.baseline);
    rep->forecast_cv_windows = static_cast<int>(h.r_true.size());
    if (!h.r_true.empty()) {
      model->forecast.residual_weight = ChooseResidualWeight(h, config, params, num_folds, J, rep);
      if (params.calibrate_covariance) {
        CalibrateForecast(h.r_true, h.r_pred, h.r_var, h.r_speed, config, params, &model->forecast, rep);
      }
    }
  }
  rep->residual_weight = model->forecast.residual_weight;
  if (!std::isfinite(model->forecast.motion_offset)) model->forecast.reference_speed.resize(0);

  for (int c = 0; c < C; ++c) {
    Eigen::MatrixXd X, Y;
    ForecastData(samples[c], layout, config, model->forecast.baseline, &X, &Y);
    model->forecasters.push_back(FitForecaster(X, Y, params, params.seed + static_cast<std::uint64_t>(c)));
  }
}

}  // namespace iplan::intent::detail
