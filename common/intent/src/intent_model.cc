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

}  // namespace

std::string IntentModelConfig::Validate() const {
  const std::string j = joints.Validate();
  if (!j.empty()) return "joints: " + j;
  if (!(rate > 0.0) || !std::isfinite(rate)) return "rate " + std::to_string(rate) + " must be > 0";
  if (window < 2) return "window " + std::to_string(window) + " must be >= 2";
  if (horizon < 1) return "horizon " + std::to_string(horizon) + " must be >= 1";
  if (velocity_frames < 1) return "velocity_frames " + std::to_string(velocity_frames) + " must be >= 1";
  if (dtw_band < 0) return "dtw_band " + std::to_string(dtw_band) + " must be >= 0";
  if (!(sensor_noise_std >= 0.0)) return "sensor_noise_std must be >= 0";
  if (!(features.torso_motion_weight >= 0.0)) return "features.torso_motion_weight must be >= 0";
  return "";
}

std::string TrainParams::Validate() const {
  if (!(max_gap > 0.0)) return "max_gap " + std::to_string(max_gap) + " must be > 0";
  if (prefix_fractions.empty()) return "prefix_fractions is empty";
  for (double f : prefix_fractions) {
    if (!(f > 0.0 && f <= 1.0)) return "prefix fraction " + std::to_string(f) + " outside (0, 1]";
  }
  if (sigma_factors.empty() || lambdas.empty()) return "sigma_factors and lambdas must not be empty";
  for (double s : sigma_factors) if (!(s > 0.0)) return "sigma factor " + std::to_string(s) + " must be > 0";
  for (double l : lambdas) if (!(l > 0.0)) return "lambda " + std::to_string(l) + " must be > 0";
  if (belief_time_constants.empty()) return "belief_time_constants is empty";
  if (belief_motion_weighting.empty()) return "belief_motion_weighting is empty";
  for (double t : belief_time_constants) {
    if (!(t >= 0.0)) return "belief time constant " + std::to_string(t) + " must be >= 0";
  }
  if (!(belief_min_probability > 0.0 && belief_min_probability < 1.0)) {
    return "belief_min_probability " + std::to_string(belief_min_probability) + " must be in (0, 1)";
  }
  const std::string ivm_error = ivm.Validate();
  if (!ivm_error.empty() && ivm_error.find("lambda") == std::string::npos) return "ivm: " + ivm_error;
  if (pseudo_inputs < 1) return "pseudo_inputs " + std::to_string(pseudo_inputs) + " must be >= 1";
  if (forecast_stride < 1) return "forecast_stride must be >= 1";
  if (max_forecast_windows < 2) return "max_forecast_windows must be >= 2";
  if (gp_iterations < 0) return "gp_iterations must be >= 0";
  return "";
}

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

  // ---- Forecasters, one per action. ----
  t0 = std::chrono::steady_clock::now();
  const int J = layout.num_joints();
  const int H = config.horizon;
  std::mt19937_64 rng(params.seed);
  for (int c = 0; c < C; ++c) {
    struct Sample { const Track* track; int end; };
    std::vector<Sample> full, padded;
    for (const Track& t : tracks) {
      if (action_id.at(t.action) != c) continue;
      const int n = static_cast<int>(t.positions.rows());
      for (int e = 0; e < n; e += params.forecast_stride) {
        (e + H <= n - 1 ? full : padded).push_back({&t, e});
      }
    }
    bool use_padded = static_cast<int>(full.size()) < params.min_forecast_windows;
    std::vector<Sample> samples = full;
    if (use_padded) samples.insert(samples.end(), padded.begin(), padded.end());
    if (samples.size() < 2) {
      throw std::invalid_argument("TrainIntentModel: action '" + model.actions[c] +
                                  "' has fewer than two forecaster windows");
    }
    if (static_cast<int>(samples.size()) > params.max_forecast_windows) {
      std::shuffle(samples.begin(), samples.end(), rng);
      samples.resize(params.max_forecast_windows);
    }
    const int Ns = static_cast<int>(samples.size());
    Eigen::MatrixXd X(Ns, layout.forecast_input_size());
    Eigen::MatrixXd Y(Ns, H * 3 * J);
    for (int i = 0; i < Ns; ++i) {
      const Track& t = *samples[i].track;
      const int e = samples[i].end;
      const int n = static_cast<int>(t.positions.rows());
      X.row(i) = layout.ForecastInput(WindowEndingAt(t.positions, e, config.window),
                                      config.rate, config.velocity_frames).transpose();
      for (int k = 0; k < H; ++k) {
        const int f = std::min(e + k + 1, n - 1);
        Y.block(i, k * 3 * J, 1, 3 * J) = t.positions.row(f) - t.positions.row(e);
      }
    }
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
    gp.seed = params.seed + static_cast<std::uint64_t>(c);
    fc.gp = SparseGp::Fit(Xs, Ys, gp);
    fc.num_training_windows = Ns;
    model.forecasters.push_back(std::move(fc));
    rep.forecast_windows.push_back(Ns);
    rep.forecast_padded.push_back(use_padded);
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
  const Eigen::RowVectorXd now = padded.row(padded.rows() - 1);
  const double noise = model.config.sensor_noise_std * model.config.sensor_noise_std;
  Eigen::VectorXd xs, mean;
  for (int c = 0; c < C; ++c) {
    const ActionForecaster& fc = model.forecasters[c];
    ActionHypothesis& hyp = out->actions[c];
    hyp.action = model.actions[c];
    hyp.probability = p(c);
    hyp.joints.resize(static_cast<size_t>(H) * J);
    xs = (x - fc.input_mean).cwiseQuotient(fc.input_scale);
    double var = 0.0;
    fc.gp.Predict(xs, &mean, &var);
    for (int k = 0; k < H; ++k) {
      for (int j = 0; j < J; ++j) {
        JointGaussian& g = hyp.joints[static_cast<size_t>(k) * J + j];
        const int o = (k * J + j) * 3;
        g.covariance.setZero();
        for (int a = 0; a < 3; ++a) {
          g.mean(a) = now(3 * j + a) + fc.output_mean(o + a) + fc.output_scale(o + a) * mean(o + a);
          g.covariance(a, a) = var * fc.output_scale(o + a) * fc.output_scale(o + a) + noise;
        }
      }
    }
  }
}

}  // namespace iplan::intent
