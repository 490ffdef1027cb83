// Intent benchmarks (plain executable, single thread):
//  1. Per-frame inference (classification + mixture forecast) of a model with
//     10 actions, 9 joints, T = 15, M = 20 pseudo-inputs, 15 horizon steps and
//     the IVM at its import-vector cap (80). Target: p99 <= 1 ms.
//  2. Training time on the Florence 3D training split (s01,s03,s05,s07,s09)
//     with the settings of scripts/eval-intent.sh. Target: <= 2 min.
// Usage: intent_bench [--skip-training]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "iplan/intent/intent_model.h"
#include "iplan/intent/skeleton_data.h"

using namespace iplan::intent;

namespace {

// Ten synthetic actions on a 9-joint upper body: each action moves one hand
// along its own direction at its own speed (plus noise), two subjects.
SkeletonDataset SyntheticTenActions() {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  SkeletonDataset d;
  d.joint_names = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l",
                   "shoulder_r", "elbow_r", "hand_r"};
  Eigen::VectorXd rest(27);
  rest << 0, 0.5, 2, 0, 0.3, 2, 0, 0, 2, -0.2, 0.3, 2, -0.3, 0, 2, -0.3, -0.3, 2, 0.2, 0.3, 2,
      0.3, 0, 2, 0.3, -0.3, 2;
  int id = 0;
  for (const char* subject : {"s1", "s2"}) {
    for (int a = 0; a < 10; ++a) {
      const double angle = 2.0 * M_PI * a / 10.0;
      const int hand = a % 2 == 0 ? 5 : 8;
      for (int rep = 0; rep < 6; ++rep) {
        SkeletonSequence s;
        s.id = "syn" + std::to_string(id++);
        s.subject = subject;
        s.action = "action" + std::to_string(a);
        const int n = 90;
        s.time = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / 30.0);
        s.positions.resize(n, 27);
        for (int i = 0; i < n; ++i) {
          Eigen::VectorXd p = rest;
          const double r = 0.3 * std::sin(0.5 * M_PI * std::min(1.0, s.time(i) / (1.5 + 0.1 * rep)));
          p(3 * hand) += r * std::cos(angle);
          p(3 * hand + 1) += r * std::sin(angle);
          for (int k = 0; k < 27; ++k) p(k) += noise(rng);
          s.positions.row(i) = p.transpose();
        }
        d.sequences.push_back(std::move(s));
      }
    }
  }
  return d;
}

void Report(const char* what, std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  auto q = [&](double f) { return ms[static_cast<size_t>(f * (ms.size() - 1))]; };
  std::printf("%s: %zu frames, p50 %.3f ms, p99 %.3f ms, max %.3f ms\n", what, ms.size(), q(0.5),
              q(0.99), ms.back());
}

}  // namespace

int main(int argc, char** argv) {
  const bool skip_training = argc > 1 && std::strcmp(argv[1], "--skip-training") == 0;
  {
    const SkeletonDataset data = SyntheticTenActions();
    IntentModelConfig config;
    config.joints = DefaultJointConfig(data.joint_names);
    config.rate = 15.0;
    config.window = 15;
    config.horizon = 15;
    TrainParams params;
    params.sigma_factors = {1.0};
    params.lambdas = {1e-4};
    params.ivm.max_import = 80;
    params.ivm.stop_tolerance = 0.0;  // reach the cap: the worst case for inference
    params.pseudo_inputs = 20;
    params.gp_iterations = 30;
    const IntentModel model = TrainIntentModel(data, config, params);
    std::printf("inference model: %zu actions, %zu joints, T = %d, M = %d, horizon = %d, %zu import vectors\n",
                model.actions.size(), config.joints.joints.size(), config.window,
                model.forecasters[0].gp.num_pseudo_inputs(), config.horizon,
                model.classifier.import_windows.size());
    const std::vector<Track> tracks = MakeTracks(data, config, 0.6);
    JointMixture pred;
    std::vector<double> ms;
    for (int round = 0; round < 5; ++round) {
      for (const Track& t : tracks) {
        for (int e = 0; e < t.positions.rows(); ++e) {
          const Eigen::MatrixXd window = WindowEndingAt(t.positions, e, config.window);
          const auto t0 = std::chrono::steady_clock::now();
          PredictIntent(model, window, &pred);
          ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
      }
    }
    Report("per-frame inference (classification + mixture forecast)", ms);
  }
  if (!skip_training) {
    const SkeletonDataset all = LoadSkeletonCsv(std::string(IPLAN_SHARED_DIR) + "/data/florence3d.csv");
    const SkeletonDataset data = SelectSubjects(all, {"s01", "s03", "s05", "s07", "s09"});
    IntentModelConfig config;
    config.joints = DefaultJointConfig(data.joint_names);
    config.features.torso_motion_weight = 3.0;
    TrainParams params;
    params.lambdas = {1e-5, 1e-4, 1e-3};
    const auto t0 = std::chrono::steady_clock::now();
    TrainReport rep;
    const IntentModel model = TrainIntentModel(data, config, params, &rep);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("training on the Florence training split (%zu sequences, %zu actions): %.1f s "
                "(classifier incl. CV %.1f s, forecasters %.1f s)\n",
                data.sequences.size(), model.actions.size(), s, rep.seconds_classifier,
                rep.seconds_forecaster);
  }
  return 0;
}
