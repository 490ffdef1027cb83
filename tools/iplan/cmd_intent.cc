// `iplan intent train` and `iplan intent eval`: train an intent model
// (IVM action classifier + per-action SPGP forecasters) on recorded skeleton
// data and evaluate it. The work is done by iplan::intent; this file only
// parses options and prints.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "command_registry.h"
#include "dds_cell_model.h"
#include "iplan/intent/evaluation.h"
#include "iplan/intent/intent_model.h"
#include "iplan/intent/model_io.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cli {
namespace {

std::vector<std::string> SplitList(const std::string& text, char sep = ',') {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

std::vector<double> ParseDoubles(const std::string& text, const std::string& option) {
  std::vector<double> out;
  for (const std::string& s : SplitList(text)) {
    size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size()) throw std::invalid_argument(option + ": '" + s + "' is not a number");
    out.push_back(v);
  }
  return out;
}

// "x,y,z;x,y,z" -> object positions (m, world frame).
std::vector<Eigen::Vector3d> ParseObjects(const std::string& text) {
  std::vector<Eigen::Vector3d> out;
  for (const std::string& o : SplitList(text, ';')) {
    const std::vector<double> v = ParseDoubles(o, "--objects");
    if (v.size() != 3) {
      throw std::invalid_argument("--objects: '" + o + "' is not an x,y,z triple");
    }
    out.emplace_back(v[0], v[1], v[2]);
  }
  return out;
}

struct TrainOptions {
  std::string data, subjects, out, joints, torso, hands, objects;
  // Defaults: the settings of the figures in docs/intent.md (Florence 3D);
  // the torso weight and the lambda grid differ from the library's
  // (FrameFeatureOptions, TrainParams), see docs/intent.md "Known limits".
  std::string sigma_factors, prefixes, belief_taus;
  std::string baseline_frames, baseline_taus, residual_weights;
  bool no_calibration = false, no_mirror = false;
  int forecast_cv_folds = 5;
  std::string lambdas = "1e-5,1e-4,1e-3";
  double rate = 15.0, noise = 0.01, max_gap = 0.6, torso_weight = 3.0;
  bool normalise_size = false;
  double ivm_tolerance = 1e-3;
  int window = 15, horizon = 15, pseudo_inputs = 20, band = 3, max_import = 80, velocity_frames = 2;
  int history_samples = iplan::intent::IntentModelConfig{}.history_samples;
  int gp_iterations = 150, max_forecast_windows = 600, forecast_stride = 2;
  std::uint64_t seed = 1;
  int threads = 0;
};

struct EvalOptions {
  std::string model, data, subjects;
  // --synthetic: the cell's synthetic person (a perception.yaml) instead of --data.
  std::string synthetic;
  std::optional<std::uint64_t> synthetic_seed;
  int synthetic_people = 12;
  bool json = false;
  int stride = 1;
  // The per-person ellipsoid calibration, as the intent service's settings.
  iplan::intent::CoverageAdapterParams coverage;
};

// The model configuration from the options and the joints of `data`.
iplan::intent::IntentModelConfig MakeConfig(const TrainOptions& o,
                                            const iplan::intent::SkeletonDataset& data) {
  using namespace iplan::intent;
  IntentModelConfig config;
  // The options first; defaults only for what they leave unset, computed
  // from the chosen joints (a one-joint tracker has no default skeleton).
  JointSelection selection;
  if (!o.joints.empty()) selection.joints = SplitList(o.joints);
  if (!o.torso.empty()) selection.torso = o.torso == "none" ? std::vector<std::string>{} : SplitList(o.torso);
  if (!o.hands.empty()) selection.hands = o.hands == "none" ? std::vector<std::string>{} : SplitList(o.hands);
  try {
    config.joints = ResolveJointConfig(data.joint_names, selection);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(e.what()) + " (options --joints, --torso, --hands)");
  }
  if (!o.objects.empty()) config.joints.objects = ParseObjects(o.objects);
  if (o.normalise_size) {
    for (const char* s : {"shoulder_l", "shoulder_r"}) {
      if (std::find(config.joints.joints.begin(), config.joints.joints.end(), s) == config.joints.joints.end()) {
        throw std::invalid_argument(std::string("--normalise-size needs the model joints shoulder_l and "
                                                "shoulder_r; '") + s + "' is not one");
      }
    }
  }
  config.rate = o.rate;
  config.window = o.window;
  config.horizon = o.horizon;
  config.velocity_frames = o.velocity_frames;
  config.history_samples = o.history_samples;
  config.dtw_band = o.band;
  config.sensor_noise_std = o.noise;
  config.features.torso_motion_weight = o.torso_weight;
  config.features.normalise_body_size = o.normalise_size;
  return config;
}

iplan::intent::TrainParams MakeTrainParams(const TrainOptions& o) {
  iplan::intent::TrainParams params;
  params.max_gap = o.max_gap;
  if (!o.sigma_factors.empty()) params.sigma_factors = ParseDoubles(o.sigma_factors, "--sigma-factors");
  if (!o.lambdas.empty()) params.lambdas = ParseDoubles(o.lambdas, "--lambdas");
  if (!o.belief_taus.empty()) params.belief_time_constants = ParseDoubles(o.belief_taus, "--belief-taus");
  if (!o.prefixes.empty()) params.prefix_fractions = ParseDoubles(o.prefixes, "--prefixes");
  if (!o.baseline_frames.empty()) {
    params.baseline_smoothing_frames.clear();
    for (double L : ParseDoubles(o.baseline_frames, "--baseline-frames")) {
      if (L != std::floor(L)) throw std::invalid_argument("--baseline-frames: " + std::to_string(L) + " is not an integer");
      params.baseline_smoothing_frames.push_back(static_cast<int>(L));
    }
  }
  if (!o.baseline_taus.empty()) params.baseline_damping_time_constants = ParseDoubles(o.baseline_taus, "--baseline-taus");
  if (!o.residual_weights.empty()) params.residual_weights = ParseDoubles(o.residual_weights, "--residual-weights");
  params.calibrate_covariance = !o.no_calibration;
  if (o.no_mirror) params.mirror_augmentation = {false};
  params.forecast_cv_folds = o.forecast_cv_folds;
  params.ivm.max_import = o.max_import;
  params.ivm.stop_tolerance = o.ivm_tolerance;
  params.pseudo_inputs = o.pseudo_inputs;
  params.gp_iterations = o.gp_iterations;
  params.max_forecast_windows = o.max_forecast_windows;
  params.forecast_stride = o.forecast_stride;
  params.seed = o.seed;
  params.threads = o.threads;
  return params;
}

// Joint set, actions and the classifier's cross-validation tables.
void PrintClassifierReport(const iplan::intent::IntentModelConfig& config,
                           const iplan::intent::IntentModel& model,
                           const iplan::intent::TrainReport& rep) {
  std::cout << "\njoints:";
  for (const std::string& j : config.joints.joints) std::cout << " " << j;
  std::cout << "\ntorso:";
  for (const std::string& j : config.joints.torso) std::cout << " " << j;
  if (config.joints.torso.empty()) std::cout << " none (features are positions in the data frame)";
  std::cout << "\nhands:";
  for (const std::string& j : config.joints.hands) std::cout << " " << j;
  if (config.joints.hands.empty()) std::cout << " none";
  std::cout << "\nactions:";
  for (const std::string& a : model.actions) std::cout << " " << a;
  std::cout << "\nclassifier: " << rep.num_classifier_samples << " windows, median DTW "
            << rep.median_dtw << " m\n  cross-validation (leave one subject out):\n"
            << "    mirrored  sigma_m  lambda   logloss  accuracy\n";
  for (const auto& row : rep.cv_table) {
    std::cout << "    " << (row[0] != 0.0 ? "yes" : "no ") << "  " << row[1] << "  " << row[2] << "  " << row[3]
              << "  " << row[4] << "\n";
  }
  std::cout << "  chosen sigma " << rep.sigma << " m, lambda " << rep.lambda << ", "
            << (rep.mirror_augmentation ? "with" : "without") << " mirror images, " << rep.num_import_vectors
            << " import vectors, " << rep.seconds_classifier << " s\n";
  if (!rep.belief_cv_table.empty()) {
    std::cout << "  belief filter over successive windows, cross-validation (leave one subject out):\n"
              << "    motion_weighted  tau_s  logloss  accuracy\n";
    for (const auto& row : rep.belief_cv_table) {
      std::cout << "    " << (row[0] != 0.0 ? "yes" : "no ") << "  " << row[1] << "  " << row[2]
                << "  " << row[3] << "\n";
    }
  }
  std::cout << "  chosen belief filter: time constant " << rep.belief_time_constant << " s, "
            << (rep.belief_motion_weighted ? "motion weighted" : "not motion weighted");
  if (!rep.belief_cv_accuracy_by_prefix.empty()) {
    std::cout << "\n  its cross-validated accuracy at the training prefixes:";
    for (double a : rep.belief_cv_accuracy_by_prefix) std::cout << " " << 100.0 * a << " %";
  }
}

// Forecaster windows and the kinematic baseline table (best tau per L).
void PrintBaselineReport(const iplan::intent::TrainParams& params,
                         const iplan::intent::TrainReport& rep) {
  std::cout << "\nforecasters (" << params.pseudo_inputs << " pseudo-inputs each): windows per action:";
  for (size_t c = 0; c < rep.forecast_windows.size(); ++c) {
    std::cout << " " << rep.forecast_windows[c] << (rep.forecast_padded[c] ? "*" : "");
  }
  std::cout << (std::find(rep.forecast_padded.begin(), rep.forecast_padded.end(), true) !=
                        rep.forecast_padded.end()
                    ? "  (* short clips: futures past the recording end hold the last pose)"
                    : "")
            << "\n  kinematic baseline (least-squares line over L frames, velocity decaying with tau),\n"
            << "  mean joint error over all steps on the training windows; best tau per L:\n"
            << "    L  tau_s  error_m\n";
  std::map<int, std::array<double, 3>> best_per_frames;
  for (const auto& row : rep.baseline_table) {
    auto [it, fresh] = best_per_frames.emplace(static_cast<int>(row[0]), row);
    if (!fresh && row[2] < it->second[2]) it->second = row;
  }
  for (const auto& [L, row] : best_per_frames) {
    std::cout << "    " << L << "  " << (L == 1 ? 0.0 : row[1]) << "  " << row[2] << "\n";
  }
  std::cout << "  (holding the last pose: " << rep.error_const_position << " m)\n  chosen L "
            << rep.baseline.smoothing_frames << ", tau " << rep.baseline.damping_time_constant
            << " s (the best line only if it beats holding by more than one standard error across the folds)\n";
}

// The forecaster cross-validation: residual weight, activity offset, coverage.
void PrintForecastCvReport(const iplan::intent::TrainReport& rep) {
  if (rep.forecast_cv_folds <= 0) {
    std::cout << "  no forecaster cross-validation (fewer than two training groups): w = 1, uncalibrated\n";
    return;
  }
  std::cout << "  residual weight, cross-validation (" << rep.forecast_cv_folds
            << " folds: the training subjects, or with one subject its sequences; "
            << rep.forecast_cv_windows << " held-out windows), held-out mean joint error [m]:\n"
            << "    w  step~0.5s  last_step  all_steps\n";
  for (const auto& row : rep.residual_cv_table) {
    std::cout << "    " << row[0] << "  " << row[1] << "  " << row[2] << "  " << row[3] << "\n";
  }
  std::cout << "  chosen w " << rep.residual_weight
            << " (the smallest within one standard error, across the folds, of the lowest all_steps error)\n";
  if (!rep.motion_cv_table.empty()) {
    std::cout << "  covariance activity offset m0, held-out (after calibration):\n"
              << "    m0_m_per_s  nll  coverage\n";
    for (const auto& row : rep.motion_cv_table) {
      std::cout << "    " << row[0] << "  " << row[1] << "  " << 100.0 * row[2] << " %\n";
    }
    std::cout << "  chosen m0 " << rep.motion_offset << " m/s\n";
  }
  std::cout << "  held-out 95 % coverage " << 100.0 * rep.cv_coverage_raw
            << " % raw, " << 100.0 * rep.cv_coverage_calibrated << " % calibrated (variance scales min "
            << rep.variance_scale_min << ", median " << rep.variance_scale_median << ", max "
            << rep.variance_scale_max << ")\n";
}

void RunTrain(const TrainOptions& o) {
  using namespace iplan::intent;
  const SkeletonDataset all = LoadSkeletonCsv(o.data);
  const SkeletonDataset data = SelectSubjects(all, SplitList(o.subjects));
  const IntentModelConfig config = MakeConfig(o, data);
  const TrainParams params = MakeTrainParams(o);

  const auto t0 = std::chrono::steady_clock::now();
  TrainReport rep;
  const IntentModel model = TrainIntentModel(data, config, params, &rep);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SaveIntentModel(model, o.out);

  std::cout << "trained on " << data.sequences.size() << " sequences of subjects " << o.subjects;
  PrintClassifierReport(config, model, rep);
  PrintBaselineReport(params, rep);
  PrintForecastCvReport(rep);
  std::cout << "  " << rep.seconds_forecaster << " s\ntraining time: " << seconds
            << " s\nmodel written to " << o.out << "\n";
}

void RunEval(const EvalOptions& o) {
  using namespace iplan::intent;
  const IntentModel model = LoadIntentModel(o.model);
  SkeletonDataset data;
  std::string source;
  if (!o.synthetic.empty()) {
    if (!o.data.empty() || !o.subjects.empty()) throw std::invalid_argument("--synthetic replaces --data and --subjects");
    if (o.synthetic_people < 1) throw std::invalid_argument("--people must be >= 1");
    // Fresh people: not the training demonstrations' seed.
    const std::uint64_t seed = o.synthetic_seed.value_or(CellPersonSeed(o.synthetic) + 1000);
    data = RecordCellEpisodes(o.synthetic, seed, o.synthetic_people);
    source = "the synthetic person of " + o.synthetic + " (" + std::to_string(o.synthetic_people) +
             " people x 2 episodes of the script, seed " + std::to_string(seed) + ")";
  } else {
    if (o.data.empty() || o.subjects.empty()) throw std::invalid_argument("--data and --subjects are required (or --synthetic)");
    data = SelectSubjects(LoadSkeletonCsv(o.data), SplitList(o.subjects));
    source = o.data + " (subjects " + o.subjects + ")";
  }
  EvalParams params;
  params.forecast_stride = o.stride;
  params.coverage = o.coverage;
  const EvalReport report = EvaluateIntentModel(model, data, params);
  if (o.json) {
    std::cout << EvalReportToJson(report) << "\n";
  } else {
    std::cout << "model " << o.model << " on " << source << "\n" << EvalReportToText(report);
  }
}

template <typename F>
void Guarded(const F& f) {
  try {
    f();
    SetExitCode(0);
  } catch (const std::exception& e) {
    std::cerr << "iplan intent: error: " << e.what() << "\n";
    SetExitCode(1);
  }
}

// `iplan intent eval`.
void AddEvalCommand(CLI::App* intent) {
  auto eval_opts = std::make_shared<EvalOptions>();
  CLI::App* eval = intent->add_subcommand("eval", "Evaluate an intent model on a skeleton CSV");
  EvalOptions& e = *eval_opts;
  eval->add_option("--model", e.model, "Model file")->required();
  eval->add_option("--data", e.data, "Skeleton CSV (shared layout)");
  eval->add_option("--subjects", e.subjects, "Test subjects, comma separated");
  eval->add_option("--synthetic", e.synthetic,
                   "Instead of --data: the synthetic person of this perception.yaml (the cell's) doing its script, "
                   "fresh people; reaching phases are scored separately");
  eval->add_option("--seed", e.synthetic_seed, "With --synthetic: generator seed (default: the person's seed + 1000)");
  eval->add_option("--people", e.synthetic_people, "With --synthetic: simulated people")->capture_default_str();
  eval->add_option("--stride", e.stride, "Frames between evaluated forecast windows")->capture_default_str();
  eval->add_option("--coverage-halving-time", e.coverage.halving_time,
                   "s; each person's ellipsoids follow their matured forecasts (95 % inside), as the intent "
                   "service's coverage_halving_time; 0: the model's own covariances")
      ->capture_default_str();
  eval->add_option("--coverage-carry-over", e.coverage.carry_over,
                   "true: each person starts from the ellipsoid scales the one before ended with (the recording's "
                   "sequences are people one after another in one cell), as the intent service's "
                   "coverage_carry_over; false: from the model's")
      ->capture_default_str();
  eval->add_flag("--json", e.json, "Print the report as JSON");
  eval->callback([eval_opts] { Guarded([&] { RunEval(*eval_opts); }); });
}

const bool kRegistered = RegisterCommand("intent", [](CLI::App& app) {
  CLI::App* intent = app.add_subcommand(
      "intent", "Human intent: train and evaluate the action classifier and motion forecaster");
  intent->require_subcommand(1);

  auto train_opts = std::make_shared<TrainOptions>();
  CLI::App* train = intent->add_subcommand(
      "train", "Train an intent model from a skeleton CSV (defaults: the settings of the Florence figures in "
               "docs/intent.md)");
  TrainOptions& t = *train_opts;
  train->add_option("--data", t.data, "Skeleton CSV (shared layout)")->required();
  train->add_option("--subjects", t.subjects, "Training subjects, comma separated")->required();
  train->add_option("--out", t.out, "Model file to write")->required();
  train->add_option("--joints", t.joints,
                    "Model joints, any names of the data, 1 or more (default: the upper-body set found in the "
                    "data, else every joint the data has, e.g. a one-joint wrist recording)");
  train->add_option("--torso", t.torso,
                    "Joints whose mean is the torso reference, or 'none': positions in the data frame "
                    "(default: torso, spine, or shoulder_l+shoulder_r among the model joints, else all model "
                    "joints: for one joint, itself)");
  train->add_option("--hands", t.hands,
                    "Hand joints for object distances, or 'none' (default: hand_l/hand_r, else "
                    "wrist_l/wrist_r, among the model joints)");
  train->add_option("--objects", t.objects, "Task objects 'x,y,z;x,y,z' (m, data frame)");
  train->add_option("--rate", t.rate, "Model rate, Hz")->capture_default_str();
  train->add_option("--window,-T", t.window, "Window length T, frames")->capture_default_str();
  train->add_option("--horizon", t.horizon, "Forecast horizon, frames")->capture_default_str();
  train->add_option("--velocity-frames", t.velocity_frames,
                    "Forecaster input velocities: finite differences over this many frames")->capture_default_str();
  train->add_option("--history-samples", t.history_samples,
                    "Forecaster input: each joint's displacement since this many earlier frames of the window")
      ->capture_default_str();
  train->add_option("--pseudo-inputs,-M", t.pseudo_inputs, "SPGP pseudo-inputs per action")->capture_default_str();
  train->add_option("--band", t.band, "DTW Sakoe-Chiba band, frames")->capture_default_str();
  train->add_option("--max-import", t.max_import, "Maximum IVM import vectors")->capture_default_str();
  train->add_option("--ivm-tolerance", t.ivm_tolerance, "IVM stopping: relative decrease over 3 additions")->capture_default_str();
  train->add_option("--sigma-factors", t.sigma_factors, "CV kernel widths x median DTW (default 0.5,1,2)");
  train->add_option("--lambdas", t.lambdas, "CV regularisers")->capture_default_str();
  train->add_option("--belief-taus", t.belief_taus,
                    "CV belief-filter time constants, s; inf allowed (default 0,0.25,0.5,1,2,4,inf)");
  train->add_option("--prefixes", t.prefixes, "Training prefix fractions (default 0.2,...,1.0)");
  train->add_option("--baseline-frames", t.baseline_frames,
                    "Kinematic baseline: least-squares frames L tried (default 1,2,3,4,5,6,8,10)");
  train->add_option("--baseline-taus", t.baseline_taus,
                    "Kinematic baseline: velocity decay time constants tried, s; inf allowed "
                    "(default 0,0.1,0.2,0.3,0.5,0.75,1,1.5,2,inf)");
  train->add_option("--residual-weights", t.residual_weights,
                    "CV weights of the SPGP residual over the baseline (default 0,0.25,0.5,0.75,1)");
  train->add_flag("--no-calibration", t.no_calibration, "Do not calibrate the forecast covariances");
  train->add_flag("--no-mirror", t.no_mirror,
                  "Do not try mirror images of the training windows (the other hand) in the classifier's "
                  "cross-validation");
  train->add_option("--forecast-cv-folds", t.forecast_cv_folds,
                    "Forecaster CV folds (training subjects, or one subject's sequences)")->capture_default_str();
  train->add_option("--gp-iterations", t.gp_iterations, "L-BFGS iterations per action")->capture_default_str();
  train->add_option("--max-forecast-windows", t.max_forecast_windows, "Forecaster windows per action")->capture_default_str();
  train->add_option("--forecast-stride", t.forecast_stride, "Frames between forecaster windows")->capture_default_str();
  train->add_option("--noise", t.noise, "Sensor noise std added to covariances, m")->capture_default_str();
  train->add_option("--max-gap", t.max_gap, "Recording gaps longer than this split sequences, s")->capture_default_str();
  train->add_option("--torso-weight", t.torso_weight, "Classifier weight of torso motion")->capture_default_str();
  train->add_flag("--normalise-size", t.normalise_size,
                  "Classifier features divided by shoulder width (needs joints shoulder_l, shoulder_r)");
  train->add_option("--seed", t.seed, "Random seed")->capture_default_str();
  train->add_option("--threads", t.threads,
                    "Threads for the classifier's cross-validation folds (0: one per hardware thread); the model "
                    "does not depend on it")
      ->check(CLI::Range(0, 256))
      ->capture_default_str();
  train->callback([train_opts] { Guarded([&] { RunTrain(*train_opts); }); });

  AddEvalCommand(intent);
});

}  // namespace
}  // namespace iplan::cli
