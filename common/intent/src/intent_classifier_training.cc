// Training of the action classifier, METHOD.md section 2: windows of the
// training tracks at the early-prediction prefixes, the DTW kernel, the
// multi-class IVM with (sigma, lambda) chosen by leave-one-subject-out
// cross-validation, and the belief filter over successive windows chosen the
// same way (docs/intent.md, pipeline steps 3, 4 and 7).
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <set>
#include <thread>
#include <vector>

#include "intent_training.h"
#include "iplan/intent/belief_filter.h"
#include "iplan/intent/dtw.h"

namespace iplan::intent::detail {
namespace {

struct ClassifierSamples {
  std::vector<Eigen::MatrixXd> windows;  // (F, T) each
  std::vector<int> labels;
  std::vector<int> subject;              // fold id
  std::vector<bool> mirrored;            // a mirror image (after all the recorded windows)
  int num_recorded = 0;                  // windows before the mirror images
};

// The rows of the windows ending at the prefix fractions of a track: of
// the whole track, or with frame actions of each stretch of one action;
// each with the index of its fraction.
std::vector<std::pair<int, int>> PrefixEndList(const Track& t, const std::vector<double>& fractions) {
  const int n = static_cast<int>(t.positions.rows());
  std::vector<std::pair<int, int>> ends;
  for (int begin = 0, end = 0; begin < n; begin = end) {
    end = begin + 1;
    while (end < n && ActionAt(t, end) == ActionAt(t, begin)) ++end;
    for (size_t i = 0; i < fractions.size(); ++i) {
      const int e = begin + std::max(1, static_cast<int>(std::ceil(fractions[i] * (end - begin) - 1e-9))) - 1;
      ends.emplace_back(e, static_cast<int>(i));
    }
  }
  return ends;
}

// The distinct rows of PrefixEndList.
std::set<int> PrefixEnds(const Track& t, const std::vector<double>& fractions) {
  std::set<int> ends;
  for (const auto& [e, i] : PrefixEndList(t, fractions)) ends.insert(e);
  return ends;
}

// ---- Classifier samples: windows ending at prefix fractions. ----
// With `mirror`, their mirror images follow (FeatureLayout::MirroredWindow).
ClassifierSamples MakeClassifierSamples(const TrainingGroups& g, const FeatureLayout& layout,
                                        const IntentModelConfig& config,
                                        const TrainParams& params, bool mirror) {
  ClassifierSamples cs;
  std::vector<Eigen::MatrixXd> images;
  for (const Track& t : g.tracks) {
    const std::set<int> ends = PrefixEnds(t, params.prefix_fractions);
    for (int e : ends) {
      const Eigen::MatrixXd window = WindowEndingAt(t.positions, e, config.window);
      cs.windows.push_back(layout.FrameFeatures(window).transpose());
      cs.labels.push_back(g.action_id.at(ActionAt(t, e)));
      cs.subject.push_back(g.subject_id.at(t.subject));
      if (mirror) images.push_back(layout.FrameFeatures(layout.MirroredWindow(window)).transpose());
    }
  }
  cs.num_recorded = static_cast<int>(cs.windows.size());
  cs.mirrored.assign(cs.windows.size(), false);
  for (size_t i = 0; i < images.size(); ++i) {
    cs.windows.push_back(std::move(images[i]));
    cs.labels.push_back(cs.labels[i]);
    cs.subject.push_back(cs.subject[i]);
    cs.mirrored.push_back(true);
  }
  return cs;
}

// The rows a classifier is trained on: every subject but `held_out` (-1:
// none), mirror images only with `mirror`.
std::vector<int> TrainingRows(const ClassifierSamples& cs, int held_out, bool mirror) {
  std::vector<int> rows;
  for (int i = 0; i < static_cast<int>(cs.windows.size()); ++i) {
    if (cs.subject[i] != held_out && (mirror || !cs.mirrored[i])) rows.push_back(i);
  }
  return rows;
}

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

// The median of the off-diagonal DTW distances (the unit of sigma), >= 1e-9;
// 1 without pairs.
double MedianDtw(const Eigen::MatrixXd& Dm) {
  const int N = static_cast<int>(Dm.rows());
  std::vector<double> off;
  off.reserve(static_cast<size_t>(N) * (N - 1) / 2);
  for (int i = 0; i < N; ++i) for (int j = i + 1; j < N; ++j) off.push_back(Dm(i, j));
  std::nth_element(off.begin(), off.begin() + off.size() / 2, off.end());
  return off.empty() ? 1.0 : std::max(off[off.size() / 2], 1e-9);
}

Eigen::MatrixXd KernelFromDtw(const Eigen::MatrixXd& D, double sigma) {
  return (-D.array().square() / (2.0 * sigma * sigma)).exp().matrix();
}

// The IVM fitted on the samples `tr` of the kernel K at regulariser lambda.
IvmModel FitIvmOnRows(const Eigen::MatrixXd& K, const ClassifierSamples& cs,
                      const std::vector<int>& tr, int C, const TrainParams& params,
                      double lambda) {
  Eigen::MatrixXd Ktr(tr.size(), tr.size());
  std::vector<int> ytr;
  for (size_t a = 0; a < tr.size(); ++a) {
    ytr.push_back(cs.labels[tr[a]]);
    for (size_t b = 0; b < tr.size(); ++b) Ktr(a, b) = K(tr[a], tr[b]);
  }
  IvmParams ip = params.ivm;
  ip.lambda = lambda;
  return FitIvm(Ktr, ytr, C, ip);
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

// Leave-one-subject-out at (K, lambda, mirror): the held-out log-loss summed
// over the recorded samples and the number classified correctly.
// The folds run on up to TrainParams::threads threads; each writes only its
// own sums, added in fold order afterwards, so the result does not depend on
// the thread count.
void LeaveOneSubjectOut(const Eigen::MatrixXd& K, const ClassifierSamples& cs, int num_subjects,
                        int C, const TrainParams& params, double lambda, bool mirror, double* loss,
                        int* correct) {
  std::vector<double> fold_loss(static_cast<size_t>(num_subjects), 0.0);
  std::vector<int> fold_correct(static_cast<size_t>(num_subjects), 0);
  auto run_fold = [&](int fold) {
    const std::vector<int> tr = TrainingRows(cs, fold, mirror);
    std::vector<int> te;
    for (int i = 0; i < cs.num_recorded; ++i) {
      if (cs.subject[i] == fold) te.push_back(i);
    }
    if (te.empty() || tr.empty()) return;
    const IvmModel ivm = FitIvmOnRows(K, cs, tr, C, params, lambda);
    const Eigen::MatrixXd P = PredictRows(ivm, K, tr, te);
    std::vector<int> yte;
    for (int i : te) yte.push_back(cs.labels[i]);
    fold_loss[static_cast<size_t>(fold)] = MeanLogLoss(P, yte) * te.size();
    for (size_t r = 0; r < te.size(); ++r) {
      Eigen::Index arg;
      P.row(static_cast<Eigen::Index>(r)).maxCoeff(&arg);
      if (arg == yte[r]) ++fold_correct[static_cast<size_t>(fold)];
    }
  };
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = std::min(num_subjects, params.threads > 0 ? params.threads : hardware);
  if (threads <= 1) {
    for (int fold = 0; fold < num_subjects; ++fold) run_fold(fold);
  } else {
    std::vector<std::exception_ptr> failed(static_cast<size_t>(threads));
    std::vector<std::thread> pool;
    for (int w = 0; w < threads; ++w) {
      pool.emplace_back([&, w] {
        try {
          for (int fold = w; fold < num_subjects; fold += threads) run_fold(fold);
        } catch (...) {
          failed[static_cast<size_t>(w)] = std::current_exception();
        }
      });
    }
    for (std::thread& t : pool) t.join();
    for (const std::exception_ptr& e : failed) {
      if (e) std::rethrow_exception(e);
    }
  }
  for (int fold = 0; fold < num_subjects; ++fold) {
    *loss += fold_loss[static_cast<size_t>(fold)];
    *correct += fold_correct[static_cast<size_t>(fold)];
  }
}

struct KernelChoice {
  double sigma = 0.0;
  double lambda = 0.0;
  bool mirror = false;  // trained on the mirror images too
};

// ---- Cross-validation over (mirror, sigma, lambda), leave-one-subject-out. ----
// Without two subjects or a grid, the middle of the grids and the first
// mirror entry.
KernelChoice ChooseKernel(const ClassifierSamples& cs, const Eigen::MatrixXd& Dm, double median,
                          const std::vector<bool>& mirror_grid, int num_subjects, int C,
                          const TrainParams& params, TrainReport* rep) {
  const int N = cs.num_recorded;
  double best_loss = std::numeric_limits<double>::infinity();
  KernelChoice best;
  best.sigma = params.sigma_factors[params.sigma_factors.size() / 2] * median;
  best.lambda = params.lambdas[params.lambdas.size() / 2];
  best.mirror = mirror_grid.front();
  if (num_subjects < 2 ||
      (params.sigma_factors.size() <= 1 && params.lambdas.size() <= 1 && mirror_grid.size() <= 1)) {
    return best;
  }
  for (const bool mirror : mirror_grid) {
    for (double sf : params.sigma_factors) {
      const double sigma = sf * median;
      const Eigen::MatrixXd K = KernelFromDtw(Dm, sigma);
      for (double lambda : params.lambdas) {
        double loss = 0.0;
        int correct = 0;
        LeaveOneSubjectOut(K, cs, num_subjects, C, params, lambda, mirror, &loss, &correct);
        loss /= N;
        rep->cv_table.push_back({mirror ? 1.0 : 0.0, sigma, lambda, loss, static_cast<double>(correct) / N});
        if (loss < best_loss) {
          best_loss = loss;
          best = {sigma, lambda, mirror};
        }
      }
    }
  }
  return best;
}

// Per training track: the held-out fold's probabilities of the windows
// ending at every frame (n, C), and their WindowMotion (n).
struct HeldOutFrames {
  std::vector<Eigen::MatrixXd> probs;
  std::vector<Eigen::VectorXd> motion;
};

HeldOutFrames HeldOutFrameProbabilities(const TrainingGroups& g, const ClassifierSamples& cs,
                                        const Eigen::MatrixXd& K, const KernelChoice& kc,
                                        const FeatureLayout& layout,
                                        const IntentModelConfig& config,
                                        const TrainParams& params) {
  const int C = g.num_actions;
  HeldOutFrames h;
  h.probs.resize(g.tracks.size());
  h.motion.resize(g.tracks.size());
  std::vector<double> ws;
  for (int fold = 0; fold < g.num_subjects; ++fold) {
    const std::vector<int> tr = TrainingRows(cs, fold, kc.mirror);
    if (tr.empty()) continue;
    const IvmModel ivm = FitIvmOnRows(K, cs, tr, C, params, kc.lambda);
    const Eigen::Index q = ivm.import_index.size();
    Eigen::VectorXd k(q), p;
    for (size_t ti = 0; ti < g.tracks.size(); ++ti) {
      const Track& t = g.tracks[ti];
      if (g.subject_id.at(t.subject) != fold) continue;
      const int n = static_cast<int>(t.positions.rows());
      h.probs[ti].resize(n, C);
      h.motion[ti].resize(n);
      for (int e = 0; e < n; ++e) {
        const Eigen::MatrixXd window = WindowEndingAt(t.positions, e, config.window);
        h.motion[ti](e) = WindowMotion(window);
        const Eigen::MatrixXd f = layout.FrameFeatures(window).transpose();
        for (Eigen::Index s = 0; s < q; ++s) {
          const double d = DtwDistanceColumns(f, cs.windows[tr[ivm.import_index(s)]],
                                              config.dtw_band, &ws);
          k(s) = DtwKernel(d, kc.sigma);
        }
        ivm.Probabilities(k, &p);
        h.probs[ti].row(e) = p.transpose();
      }
    }
  }
  return h;
}

// A cross-validation score: held-out mean log-loss and accuracy.
struct CvScore {
  double loss = 0.0;
  double accuracy = 0.0;
  std::vector<double> accuracy_by_prefix;  // per prefix fraction
};

// The belief filter (tau, motion_weighted) run over every frame of the
// held-out tracks, scored at the training prefix fractions.
CvScore ScoreBeliefFilter(const TrainingGroups& g, const HeldOutFrames& h, double tau,
                          bool motion_weighted, const IntentModelConfig& config,
                          const TrainParams& params) {
  BeliefFilter filter(g.num_actions,
                      BeliefFilterParams{tau, params.belief_min_probability, motion_weighted});
  double loss = 0.0;
  int correct = 0, count = 0;
  const size_t F = params.prefix_fractions.size();
  std::vector<double> prefix_correct(F, 0.0), prefix_count(F, 0.0);
  for (size_t ti = 0; ti < g.tracks.size(); ++ti) {
    const Eigen::MatrixXd& P = h.probs[ti];
    if (P.rows() == 0) continue;
    std::map<int, std::vector<int>> ends;  // row -> its prefix fractions
    for (const auto& [e, i] : PrefixEndList(g.tracks[ti], params.prefix_fractions)) ends[e].push_back(i);
    filter.Reset();
    for (int e = 0; e <= ends.rbegin()->first; ++e) {
      if (e + 1 < config.window) filter.Reset();  // partial window: see BeliefFilter
      filter.Update(P.row(e).transpose(), e / config.rate,
                    motion_weighted ? std::max(h.motion[ti](e), 1e-6) : 1.0);
      const auto it = ends.find(e);
      if (it == ends.end()) continue;
      const int truth = g.action_id.at(ActionAt(g.tracks[ti], e));
      loss -= std::log(std::max(filter.probabilities()(truth), 1e-12));
      const bool right = filter.MostLikely() == truth;
      if (right) ++correct;
      ++count;
      for (int i : it->second) {
        prefix_correct[i] += right ? 1.0 : 0.0;
        prefix_count[i] += 1.0;
      }
    }
  }
  loss /= std::max(1, count);
  CvScore score{loss, static_cast<double>(correct) / std::max(1, count), {}};
  for (size_t i = 0; i < F; ++i) score.accuracy_by_prefix.push_back(prefix_correct[i] / std::max(1.0, prefix_count[i]));
  return score;
}

// ---- Belief filter time constant, leave-one-subject-out at (sigma, lambda). ----
void ChooseBeliefFilter(const TrainingGroups& g, const ClassifierSamples& cs,
                        const Eigen::MatrixXd& Dm, const KernelChoice& kc,
                        const FeatureLayout& layout, const IntentModelConfig& config,
                        const TrainParams& params, BeliefFilterParams* belief, TrainReport* rep) {
  belief->min_probability = params.belief_min_probability;
  belief->time_constant = params.belief_time_constants.front();
  belief->motion_weighted = params.belief_motion_weighting.front();
  if (g.num_subjects < 2 ||
      params.belief_time_constants.size() * params.belief_motion_weighting.size() <= 1) {
    return;
  }
  const Eigen::MatrixXd K = KernelFromDtw(Dm, kc.sigma);
  const HeldOutFrames h = HeldOutFrameProbabilities(g, cs, K, kc, layout, config, params);
  double best_belief_loss = std::numeric_limits<double>::infinity();
  for (const bool motion_weighted : params.belief_motion_weighting)
  for (double tau : params.belief_time_constants) {
    const CvScore score = ScoreBeliefFilter(g, h, tau, motion_weighted, config, params);
    rep->belief_cv_table.push_back({motion_weighted ? 1.0 : 0.0, tau, score.loss, score.accuracy});
    if (score.loss < best_belief_loss) {
      best_belief_loss = score.loss;
      belief->time_constant = tau;
      belief->motion_weighted = motion_weighted;
      rep->belief_cv_accuracy_by_prefix = score.accuracy_by_prefix;
    }
  }
}

}  // namespace

void TrainClassifier(const TrainingGroups& groups, const FeatureLayout& layout,
                     const IntentModelConfig& config, const TrainParams& params,
                     ActionClassifier* classifier, TrainReport* rep) {
  // Mirror images are a candidate only when the joint set can be mirrored
  // and there is a cross-validation to decide.
  std::vector<bool> mirror_grid;
  for (const bool m : params.mirror_augmentation) {
    if (!m || (layout.CanMirror() && groups.num_subjects >= 2)) mirror_grid.push_back(m);
  }
  if (mirror_grid.empty()) mirror_grid.push_back(false);
  const bool any_mirror = std::find(mirror_grid.begin(), mirror_grid.end(), true) != mirror_grid.end();
  const ClassifierSamples cs = MakeClassifierSamples(groups, layout, config, params, any_mirror);
  const Eigen::MatrixXd Dm = DtwMatrix(cs.windows, config.dtw_band);
  const double median = MedianDtw(Dm.topLeftCorner(cs.num_recorded, cs.num_recorded));
  rep->median_dtw = median;
  rep->num_classifier_samples = cs.num_recorded;

  const KernelChoice kc =
      ChooseKernel(cs, Dm, median, mirror_grid, groups.num_subjects, groups.num_actions, params, rep);
  {
    const Eigen::MatrixXd K = KernelFromDtw(Dm, kc.sigma);
    const std::vector<int> rows = TrainingRows(cs, -1, kc.mirror);
    classifier->sigma = kc.sigma;
    classifier->ivm = FitIvmOnRows(K, cs, rows, groups.num_actions, params, kc.lambda);
    for (Eigen::Index s = 0; s < classifier->ivm.import_index.size(); ++s) {
      classifier->import_windows.push_back(cs.windows[rows[classifier->ivm.import_index(s)]]);
    }
  }
  rep->sigma = kc.sigma;
  rep->lambda = kc.lambda;
  rep->mirror_augmentation = kc.mirror;

  ChooseBeliefFilter(groups, cs, Dm, kc, layout, config, params, &classifier->belief, rep);
  rep->belief_time_constant = classifier->belief.time_constant;
  rep->belief_motion_weighted = classifier->belief.motion_weighted;
  rep->num_import_vectors = static_cast<int>(classifier->import_windows.size());
}

}  // namespace iplan::intent::detail
