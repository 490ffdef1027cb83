#include "iplan/intent/intent_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>

#include "iplan/intent/dtw.h"
#include "iplan/intent/forecast_calibration.h"

namespace iplan::intent {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

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

struct ClassifierSamples {
  std::vector<Eigen::MatrixXd> windows;  // (F, T) each
  std::vector<int> labels;
  std::vector<int> subject;              // fold id
};

Eigen::MatrixXd DtwMatrix(const std::vector<Eigen::MatrixXd>& w, int band) {
  const Eigen::Index N = static_cast<Eigen::Index>(w.size());
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(N, N);
  std::vector<double> ws;
  for (Eigen::Index i = 0; i < N; ++i) {
    for (Eigen::Index j = i + 1; j < N; ++j) {
      D(i, j) = D(j, i) = DtwDistanceColumns(w[i], w[j], band, &ws);
    }
  }
  return D;
}

Eigen::MatrixXd KernelFromDtw(const Eigen::MatrixXd& D, double sigma) {
  return (-D.array().square() / (2.0 * sigma * sigma)).exp().matrix();
}

// Kernel-values probabilities for rows `test` against the fitted import set.
Eigen::MatrixXd PredictRows(const IvmModel& ivm, const Eigen::MatrixXd& K,
                            const std::vector<int>& train_rows,
                            const std::vector<int>& test_rows) {
  const Eigen::Index q = ivm.import_index.size();
  Eigen::MatrixXd P(static_cast<Eigen::Index>(test_rows.size()), ivm.num_classes());
  Eigen::VectorXd k(q), p;
  for (size_t t = 0; t < test_rows.size(); ++t) {
    for (Eigen::Index s = 0; s < q; ++s) k(s) = K(test_rows[t], train_rows[ivm.import_index(s)]);
    ivm.Probabilities(k, &p);
    P.row(static_cast<Eigen::Index>(t)) = p.transpose();
  }
  return P;
}

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
  X->resize(N, layout.forecast_input_size());
  Y->resize(N, H * 3 * J);
  if (speeds != nullptr) speeds->resize(N, J);
  Eigen::MatrixXd base;
  Eigen::VectorXd u;
  for (int i = 0; i < N; ++i) {
    const Track& t = *samples[i].track;
    const Eigen::MatrixXd window = WindowEndingAt(t.positions, samples[i].end, config.window);
    X->row(i) = layout.ForecastInput(window, config.rate, config.velocity_frames).transpose();
    ExtrapolateKinematic(window, baseline, config.rate, H, &base);
    const Eigen::MatrixXd future = Future(t, samples[i].end, H);
    for (int k = 0; k < H; ++k) Y->block(i, k * 3 * J, 1, 3 * J) = future.row(k) - base.row(k);
    if (speeds != nullptr) {
      MeanJointSpeeds(window, config.rate, &u);
      speeds->row(i) = u.transpose();
    }
  }
}

// rho_j^2 of ForecastSettings for window speeds `u` (J).
double ActivityFactor(const ForecastSettings& f, const Eigen::VectorXd& u, int j) {
  if (!std::isfinite(f.motion_offset)) return 1.0;
  const double rho = (u(j) + f.motion_offset) / (f.reference_speed(j) + f.motion_offset);
  return rho * rho;
}

// Standardises X and Y and fits the SPGP of one action.
ActionForecaster FitForecaster(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                               const TrainParams& params, std::uint64_t seed) {
  const Eigen::Index Ns = X.rows();
  ActionForecaster fc;
  fc.input_mean = X.colwise().mean().transpose();
  fc.input_scale = ((X.rowwise() - fc.input_mean.transpose()).colwise().squaredNorm() / Ns)
                       .cwiseSqrt().transpose();
  fc.output_mean = Y.colwise().mean().transpose();
  fc.output_scale = ((Y.rowwise() - fc.output_mean.transpose()).colwise().squaredNorm() / Ns)
                        .cwiseSqrt().transpose();
  for (Eigen::Index d = 0; d < fc.input_scale.size(); ++d) {
    if (!(fc.input_scale(d) > 1e-9)) fc.input_scale(d) = 1.0;
  }
  for (Eigen::Index d = 0; d < fc.output_scale.size(); ++d) {
    if (!(fc.output_scale(d) > 1e-9)) fc.output_scale(d) = 1e-9;
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

// The (L, tau) of the grids with the lowest mean joint error of the
// extrapolation alone over all samples; fills the report's table.
KinematicBaseline ChooseBaseline(const std::vector<std::vector<ForecastSample>>& samples,
                                 const IntentModelConfig& config, const TrainParams& params,
                                 TrainReport* rep) {
  const int H = config.horizon;
  const int J = static_cast<int>(config.joints.joints.size());
  std::vector<int> frames;
  for (int L : params.baseline_smoothing_frames) {
    if (L <= config.window) frames.push_back(L);
  }
  if (frames.empty()) frames.push_back(1);
  const std::vector<double>& taus = params.baseline_damping_time_constants;
  Eigen::MatrixXd error = Eigen::MatrixXd::Zero(frames.size(), taus.size());
  Eigen::VectorXd g(H), p, v;
  long count = 0;
  double hold = 0.0;
  for (const std::vector<ForecastSample>& action : samples) {
    for (const ForecastSample& smp : action) {
      const Eigen::MatrixXd window = WindowEndingAt(smp.track->positions, smp.end, config.window);
      const Eigen::MatrixXd future = Future(*smp.track, smp.end, H);
      for (int k = 0; k < H; ++k) {
        for (int j = 0; j < J; ++j) {
          hold += (future.block<1, 3>(k, 3 * j) - window.block<1, 3>(window.rows() - 1, 3 * j)).norm();
        }
      }
      for (size_t l = 0; l < frames.size(); ++l) {
        FitLine(window, frames[l], config.rate, &p, &v);
        for (size_t ti = 0; ti < taus.size(); ++ti) {
          for (int k = 0; k < H; ++k) g(k) = DampedDisplacement((k + 1) / config.rate, taus[ti]);
          double sum = 0.0;
          for (int k = 0; k < H; ++k) {
            for (int j = 0; j < J; ++j) {
              sum += (future.row(k).segment<3>(3 * j).transpose() - p.segment<3>(3 * j) -
                      g(k) * v.segment<3>(3 * j)).norm();
            }
          }
          error(l, ti) += sum;
        }
      }
      ++count;
    }
  }
  const double denom = static_cast<double>(std::max<long>(1, count)) * H * J;
  error /= denom;
  rep->error_const_position = hold / denom;
  Eigen::Index bl = 0, bt = 0;
  error.minCoeff(&bl, &bt);
  for (size_t l = 0; l < frames.size(); ++l) {
    for (size_t ti = 0; ti < taus.size(); ++ti) {
      rep->baseline_table.push_back({static_cast<double>(frames[l]), taus[ti], error(l, ti)});
    }
  }
  KinematicBaseline b;
  b.smoothing_frames = frames[bl];
  // L = 1 has no velocity: any tau is the same; store 0.
  b.damping_time_constant = frames[bl] == 1 ? 0.0 : taus[bt];
  rep->baseline = b;
  return b;
}

}  // namespace

JointGaussian MixturePrediction::Combined(int step, int joint) const {
  JointGaussian g;
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (size_t c = 0; c < actions.size(); ++c) {
    const JointGaussian& a = At(static_cast<int>(c), step, joint);
    const double p = actions[c].probability;
    g.mean += p * a.mean;
    second += p * (a.covariance + a.mean * a.mean.transpose());
  }
  g.covariance = second - g.mean * g.mean.transpose();
  return g;
}

int MixturePrediction::MostLikely() const {
  int best = 0;
  for (size_t c = 1; c < actions.size(); ++c) {
    if (actions[c].probability > actions[best].probability) best = static_cast<int>(c);
  }
  return best;
}

std::vector<Track> MakeTracks(const SkeletonDataset& data, const IntentModelConfig& config,
                              double max_gap) {
  for (const std::string& j : config.joints.joints) {
    if (std::find(data.joint_names.begin(), data.joint_names.end(), j) == data.joint_names.end()) {
      std::string list;
      for (const std::string& a : data.joint_names) list += (list.empty() ? "" : ",") + a;
      throw std::invalid_argument("model joint '" + j + "' is not in the data (data joints: " +
                                  list + ")");
    }
  }
  const std::vector<int> idx = JointIndices(data.joint_names, config.joints.joints);
  std::vector<Track> tracks;
  for (const SkeletonSequence& s : data.sequences) {
    for (Track& t : ResampleSequence(s, idx, config.rate, max_gap)) tracks.push_back(std::move(t));
  }
  return tracks;
}

IntentModel TrainIntentModel(const SkeletonDataset& data, const IntentModelConfig& config,
                             const TrainParams& params, TrainReport* report) {
  std::string error = config.Validate();
  if (!error.empty()) throw std::invalid_argument("IntentModelConfig: " + error);
  error = params.Validate();
  if (!error.empty()) throw std::invalid_argument("TrainParams: " + error);
  const FeatureLayout layout(config.joints, config.features);
  const std::vector<Track> tracks = MakeTracks(data, config, params.max_gap);

  IntentModel model;
  model.config = config;
  std::set<std::string> action_set;
  for (const Track& t : tracks) action_set.insert(t.action);
  model.actions.assign(action_set.begin(), action_set.end());
  if (model.actions.size() < 2) {
    throw std::invalid_argument("TrainIntentModel: need at least two actions, got " +
                                std::to_string(model.actions.size()));
  }
  std::map<std::string, int> action_id, subject_id;
  for (size_t c = 0; c < model.actions.size(); ++c) action_id[model.actions[c]] = static_cast<int>(c);
  for (const Track& t : tracks) subject_id.emplace(t.subject, static_cast<int>(subject_id.size()));
  const int C = static_cast<int>(model.actions.size());
  TrainReport rep;

  // ---- Classifier samples: windows ending at prefix fractions. ----
  auto t0 = std::chrono::steady_clock::now();
  ClassifierSamples cs;
  for (const Track& t : tracks) {
    const int n = static_cast<int>(t.positions.rows());
    std::set<int> ends;
    for (double f : params.prefix_fractions) {
      ends.insert(std::max(1, static_cast<int>(std::ceil(f * n - 1e-9))) - 1);
    }
    for (int e : ends) {
      cs.windows.push_back(
          layout.FrameFeatures(WindowEndingAt(t.positions, e, config.window)).transpose());
      cs.labels.push_back(action_id.at(t.action));
      cs.subject.push_back(subject_id.at(t.subject));
    }
  }
  const int N = static_cast<int>(cs.windows.size());
  const Eigen::MatrixXd Dm = DtwMatrix(cs.windows, config.dtw_band);
  std::vector<double> off;
  off.reserve(static_cast<size_t>(N) * (N - 1) / 2);
  for (int i = 0; i < N; ++i) for (int j = i + 1; j < N; ++j) off.push_back(Dm(i, j));
  std::nth_element(off.begin(), off.begin() + off.size() / 2, off.end());
  const double median = off.empty() ? 1.0 : std::max(off[off.size() / 2], 1e-9);
  rep.median_dtw = median;
  rep.num_classifier_samples = N;

  // ---- Cross-validation over (sigma, lambda), leave-one-subject-out. ----
  const int num_subjects = static_cast<int>(subject_id.size());
  double best_loss = std::numeric_limits<double>::infinity();
  double best_sigma = params.sigma_factors[params.sigma_factors.size() / 2] * median;
  double best_lambda = params.lambdas[params.lambdas.size() / 2];
  if (num_subjects >= 2 && (params.sigma_factors.size() > 1 || params.lambdas.size() > 1)) {
    for (double sf : params.sigma_factors) {
      const double sigma = sf * median;
      const Eigen::MatrixXd K = KernelFromDtw(Dm, sigma);
      for (double lambda : params.lambdas) {
        double loss = 0.0;
        int correct = 0;
        for (int fold = 0; fold < num_subjects; ++fold) {
          std::vector<int> tr, te;
          for (int i = 0; i < N; ++i) (cs.subject[i] == fold ? te : tr).push_back(i);
          if (te.empty() || tr.empty()) continue;
          Eigen::MatrixXd Ktr(tr.size(), tr.size());
          std::vector<int> ytr;
          for (size_t a = 0; a < tr.size(); ++a) {
            ytr.push_back(cs.labels[tr[a]]);
            for (size_t b = 0; b < tr.size(); ++b) Ktr(a, b) = K(tr[a], tr[b]);
          }
          IvmParams ip = params.ivm;
          ip.lambda = lambda;
          const IvmModel ivm = FitIvm(Ktr, ytr, C, ip);
          const Eigen::MatrixXd P = PredictRows(ivm, K, tr, te);
          std::vector<int> yte;
          for (int i : te) yte.push_back(cs.labels[i]);
          loss += MeanLogLoss(P, yte) * te.size();
          for (size_t r = 0; r < te.size(); ++r) {
            Eigen::Index arg;
            P.row(static_cast<Eigen::Index>(r)).maxCoeff(&arg);
            if (arg == yte[r]) ++correct;
          }
        }
        loss /= N;
        rep.cv_table.push_back({sigma, lambda, loss, static_cast<double>(correct) / N});
        if (loss < best_loss) {
          best_loss = loss;
          best_sigma = sigma;
          best_lambda = lambda;
        }
      }
    }
  }
  {
    IvmParams ip = params.ivm;
    ip.lambda = best_lambda;
    const Eigen::MatrixXd K = KernelFromDtw(Dm, best_sigma);
    model.classifier.sigma = best_sigma;
    model.classifier.ivm = FitIvm(K, cs.labels, C, ip);
    for (Eigen::Index s = 0; s < model.classifier.ivm.import_index.size(); ++s) {
      model.classifier.import_windows.push_back(cs.windows[model.classifier.ivm.import_index(s)]);
    }
  }
  rep.sigma = best_sigma;
  rep.lambda = best_lambda;

  // ---- Belief filter time constant, leave-one-subject-out at (sigma, lambda). ----
  model.classifier.belief.min_probability = params.belief_min_probability;
  model.classifier.belief.time_constant = params.belief_time_constants.front();
  model.classifier.belief.motion_weighted = params.belief_motion_weighting.front();
  if (num_subjects >= 2 &&
      params.belief_time_constants.size() * params.belief_motion_weighting.size() > 1) {
    const Eigen::MatrixXd K = KernelFromDtw(Dm, best_sigma);
    // Per training track: the held-out fold's probabilities of the windows
    // ending at every frame (n, C).
    std::vector<Eigen::MatrixXd> frame_probs(tracks.size());
    std::vector<Eigen::VectorXd> frame_motion(tracks.size());  // WindowMotion per frame
    std::vector<double> ws;
    for (int fold = 0; fold < num_subjects; ++fold) {
      std::vector<int> tr;
      for (int i = 0; i < N; ++i) if (cs.subject[i] != fold) tr.push_back(i);
      if (tr.empty()) continue;
      Eigen::MatrixXd Ktr(tr.size(), tr.size());
      std::vector<int> ytr;
      for (size_t a = 0; a < tr.size(); ++a) {
        ytr.push_back(cs.labels[tr[a]]);
        for (size_t b = 0; b < tr.size(); ++b) Ktr(a, b) = K(tr[a], tr[b]);
      }
      IvmParams ip = params.ivm;
      ip.lambda = best_lambda;
      const IvmModel ivm = FitIvm(Ktr, ytr, C, ip);
      const Eigen::Index q = ivm.import_index.size();
      Eigen::VectorXd k(q), p;
      for (size_t ti = 0; ti < tracks.size(); ++ti) {
        const Track& t = tracks[ti];
        if (subject_id.at(t.subject) != fold) continue;
        const int n = static_cast<int>(t.positions.rows());
        frame_probs[ti].resize(n, C);
        frame_motion[ti].resize(n);
        for (int e = 0; e < n; ++e) {
          const Eigen::MatrixXd window = WindowEndingAt(t.positions, e, config.window);
          frame_motion[ti](e) = WindowMotion(window);
          const Eigen::MatrixXd f = layout.FrameFeatures(window).transpose();
          for (Eigen::Index s = 0; s < q; ++s) {
            const double d = DtwDistanceColumns(f, cs.windows[tr[ivm.import_index(s)]],
                                                config.dtw_band, &ws);
            k(s) = DtwKernel(d, best_sigma);
          }
          ivm.Probabilities(k, &p);
          frame_probs[ti].row(e) = p.transpose();
        }
      }
    }
    double best_belief_loss = std::numeric_limits<double>::infinity();
    for (const bool motion_weighted : params.belief_motion_weighting)
    for (double tau : params.belief_time_constants) {
      BeliefFilter filter(C, BeliefFilterParams{tau, params.belief_min_probability, motion_weighted});
      double loss = 0.0;
      int correct = 0, count = 0;
      for (size_t ti = 0; ti < tracks.size(); ++ti) {
        const Eigen::MatrixXd& P = frame_probs[ti];
        if (P.rows() == 0) continue;
        const int n = static_cast<int>(P.rows());
        const int truth = action_id.at(tracks[ti].action);
        std::set<int> ends;
        for (double f : params.prefix_fractions) {
          ends.insert(std::max(1, static_cast<int>(std::ceil(f * n - 1e-9))) - 1);
        }
        filter.Reset();
        for (int e = 0; e <= *ends.rbegin(); ++e) {
          if (e + 1 < config.window) filter.Reset();  // partial window: see BeliefFilter
          filter.Update(P.row(e).transpose(), e / config.rate,
                        motion_weighted ? std::max(frame_motion[ti](e), 1e-6) : 1.0);
          if (ends.count(e) == 0) continue;
          loss -= std::log(std::max(filter.probabilities()(truth), 1e-12));
          if (filter.MostLikely() == truth) ++correct;
          ++count;
        }
      }
      loss /= std::max(1, count);
      rep.belief_cv_table.push_back({motion_weighted ? 1.0 : 0.0, tau, loss,
                                     static_cast<double>(correct) / std::max(1, count)});
      if (loss < best_belief_loss) {
        best_belief_loss = loss;
        model.classifier.belief.time_constant = tau;
        model.classifier.belief.motion_weighted = motion_weighted;
      }
    }
  }
  rep.belief_time_constant = model.classifier.belief.time_constant;
  rep.belief_motion_weighted = model.classifier.belief.motion_weighted;
  rep.num_import_vectors = static_cast<int>(model.classifier.import_windows.size());
  rep.seconds_classifier = Seconds(t0);

  // ---- Forecasters, one per action (see ForecastSettings). ----
  t0 = std::chrono::steady_clock::now();
  const int J = layout.num_joints();
  const int H = config.horizon;
  std::mt19937_64 rng(params.seed);
  // CV folds: subjects, or the sequences of a single subject, round-robin.
  std::map<std::string, int> group_id;
  for (const Track& t : tracks) {
    group_id.emplace(num_subjects >= 2 ? t.subject : t.sequence_id, static_cast<int>(group_id.size()));
  }
  const int num_folds = std::min(static_cast<int>(group_id.size()), params.forecast_cv_folds);
  std::vector<std::vector<ForecastSample>> samples(C);
  for (int c = 0; c < C; ++c) {
    std::vector<ForecastSample> full, padded;
    for (const Track& t : tracks) {
      if (action_id.at(t.action) != c) continue;
      const int n = static_cast<int>(t.positions.rows());
      const int fold = group_id.at(num_subjects >= 2 ? t.subject : t.sequence_id) % std::max(1, num_folds);
      for (int e = 0; e < n; e += params.forecast_stride) {
        (e + H <= n - 1 ? full : padded).push_back({&t, e, fold});
      }
    }
    const bool use_padded = static_cast<int>(full.size()) < params.min_forecast_windows;
    samples[c] = full;
    if (use_padded) samples[c].insert(samples[c].end(), padded.begin(), padded.end());
    if (samples[c].size() < 2) {
      throw std::invalid_argument("TrainIntentModel: action '" + model.actions[c] +
                                  "' has fewer than two forecaster windows");
    }
    if (static_cast<int>(samples[c].size()) > params.max_forecast_windows) {
      std::shuffle(samples[c].begin(), samples[c].end(), rng);
      samples[c].resize(params.max_forecast_windows);
    }
    rep.forecast_windows.push_back(static_cast<int>(samples[c].size()));
    rep.forecast_padded.push_back(use_padded);
  }
  model.forecast.baseline = ChooseBaseline(samples, config, params, &rep);
  {
    // ubar_j: mean window speed of each joint over all forecaster windows.
    Eigen::VectorXd u, sum = Eigen::VectorXd::Zero(J);
    long count = 0;
    for (const std::vector<ForecastSample>& action : samples) {
      for (const ForecastSample& smp : action) {
        MeanJointSpeeds(WindowEndingAt(smp.track->positions, smp.end, config.window), config.rate, &u);
        sum += u;
        ++count;
      }
    }
    model.forecast.reference_speed = sum / static_cast<double>(std::max<long>(1, count));
  }

  // Cross-validated residual predictions: held-out true residuals, predicted
  // residual means and variances (m, m^2), one row per held-out window.
  model.forecast.residual_weight = 1.0;
  rep.forecast_cv_folds = num_folds >= 2 ? num_folds : 0;
  if (num_folds >= 2) {
    std::vector<Eigen::RowVectorXd> r_true, r_pred, r_var, r_speed;
    Eigen::VectorXd mean, var;
    for (int c = 0; c < C; ++c) {
      for (int f = 0; f < num_folds; ++f) {
        std::vector<ForecastSample> train, test;
        for (const ForecastSample& smp : samples[c]) (smp.fold == f ? test : train).push_back(smp);
        if (test.empty() || train.size() < 2) continue;
        Eigen::MatrixXd X, Y, Xt, Yt, Ut;
        ForecastData(train, layout, config, model.forecast.baseline, &X, &Y);
        ForecastData(test, layout, config, model.forecast.baseline, &Xt, &Yt, &Ut);
        const ActionForecaster fc =
            FitForecaster(X, Y, params, params.seed + static_cast<std::uint64_t>(c));
        for (Eigen::Index i = 0; i < Xt.rows(); ++i) {
          PredictResidual(fc, Xt.row(i).transpose(), &mean, &var);
          r_true.push_back(Yt.row(i));
          r_pred.push_back(mean.transpose());
          r_var.push_back(var.transpose());
          r_speed.push_back(Ut.row(i));
        }
      }
    }
    const Eigen::Index Nh = static_cast<Eigen::Index>(r_true.size());
    rep.forecast_cv_windows = static_cast<int>(Nh);
    if (Nh > 0) {
      const int k_half = std::clamp(static_cast<int>(std::lround(0.5 * config.rate)) - 1, 0, H - 1);
      double best_error = std::numeric_limits<double>::infinity();
      for (double w : params.residual_weights) {
        Eigen::VectorXd per_step = Eigen::VectorXd::Zero(H);
        for (Eigen::Index i = 0; i < Nh; ++i) {
          for (int k = 0; k < H; ++k) {
            for (int j = 0; j < J; ++j) {
              const int o = (k * J + j) * 3;
              per_step(k) += (r_true[i].segment<3>(o) - w * r_pred[i].segment<3>(o)).norm();
            }
          }
        }
        per_step /= static_cast<double>(Nh * J);
        rep.residual_cv_table.push_back({w, per_step(k_half), per_step(H - 1), per_step.mean()});
        if (per_step.mean() < best_error) {
          best_error = per_step.mean();
          model.forecast.residual_weight = w;
        }
      }
      if (params.calibrate_covariance) CalibrateForecast(r_true, r_pred, r_var, r_speed, config, params, &model.forecast, &rep);
    }
  }
  rep.residual_weight = model.forecast.residual_weight;
  if (!std::isfinite(model.forecast.motion_offset)) model.forecast.reference_speed.resize(0);

  for (int c = 0; c < C; ++c) {
    Eigen::MatrixXd X, Y;
    ForecastData(samples[c], layout, config, model.forecast.baseline, &X, &Y);
    model.forecasters.push_back(FitForecaster(X, Y, params, params.seed + static_cast<std::uint64_t>(c)));
  }
  rep.seconds_forecaster = Seconds(t0);
  if (report != nullptr) *report = rep;
  return model;
}

Eigen::VectorXd ClassifyWindow(const IntentModel& model, const Eigen::MatrixXd& window) {
  const FeatureLayout layout(model.config.joints, model.config.features);
  return ClassifyPadded(model, layout, NormaliseWindow(model, window));
}

void PredictIntent(const IntentModel& model, const Eigen::MatrixXd& window,
                   MixturePrediction* out) {
  const FeatureLayout layout(model.config.joints, model.config.features);
  const Eigen::MatrixXd padded = NormaliseWindow(model, window);
  const Eigen::VectorXd p = ClassifyPadded(model, layout, padded);
  const int C = static_cast<int>(model.actions.size());
  const int J = layout.num_joints();
  const int H = model.config.horizon;
  out->dt = 1.0 / model.config.rate;
  out->horizon = H;
  out->num_joints = J;
  out->actions.resize(C);
  const Eigen::VectorXd x = layout.ForecastInput(padded, model.config.rate,
                                                 model.config.velocity_frames);
  Eigen::MatrixXd base;
  ExtrapolateKinematic(padded, model.forecast.baseline, model.config.rate, H, &base);
  const double noise = model.config.sensor_noise_std * model.config.sensor_noise_std;
  const double w = model.forecast.residual_weight;
  const Eigen::VectorXd& scale = model.forecast.variance_scale;
  Eigen::VectorXd mean, var, speeds;
  if (std::isfinite(model.forecast.motion_offset)) MeanJointSpeeds(padded, model.config.rate, &speeds);
  for (int c = 0; c < C; ++c) {
    ActionHypothesis& hyp = out->actions[c];
    hyp.action = model.actions[c];
    hyp.probability = p(c);
    hyp.joints.resize(static_cast<size_t>(H) * J);
    PredictResidual(model.forecasters[c], x, &mean, &var);
    for (int k = 0; k < H; ++k) {
      for (int j = 0; j < J; ++j) {
        JointGaussian& g = hyp.joints[static_cast<size_t>(k) * J + j];
        const int o = (k * J + j) * 3;
        const double s = (scale.size() == 0 ? 1.0 : scale(k * J + j)) *
                         ActivityFactor(model.forecast, speeds, j);
        g.covariance.setZero();
        for (int a = 0; a < 3; ++a) {
          g.mean(a) = base(k, 3 * j + a) + w * mean(o + a);
          g.covariance(a, a) = s * (var(o + a) + noise);
        }
      }
    }
  }
}

}  // namespace iplan::intent
