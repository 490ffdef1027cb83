#include "dds_cell_model.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "services/intent/core/intent_settings.h"
#include "services/perception/core/synthetic_person.h"
#include "iplan/core/params.h"
#include "iplan/core/atomic_file.h"
#include "iplan/framework/service_file.h"
#include "iplan/intent/intent_model.h"
#include "iplan/intent/model_io.h"
#include "services/perception/perception_settings.h"

namespace iplan::cli {
namespace {

namespace fs = std::filesystem;

// Demonstrations: 6 simulated people x 2 recordings x every action, 4 s each.
constexpr int kSubjects = 6;
constexpr int kRepetitions = 2;
constexpr double kSeconds = 4.0;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Everything the trained model depends on, as text: a changed person, joint
// set or rate makes the cached model stale, and so does a model file format
// written by another build (an older file may still load, but it lacks what
// the newer training chooses, e.g. the calibrated forecast covariances).
std::string ModelKey(const perception::SyntheticPersonParams& p, const std::vector<std::string>& joints, double rate) {
  std::ostringstream k;
  k.precision(17);
  k << "iplan cell intent model v2 (demonstrations and episodes)\nformat " << intent::kIntentModelFormatVersion << "\nsubjects " << kSubjects << " repetitions " << kRepetitions << " seconds "
    << kSeconds << "\nrate " << rate << "\njoints";
  for (const auto& j : joints) k << " " << j;
  k << "\ntorso " << p.torso_W.transpose() << " rest " << p.rest_left_P.transpose() << " yaw " << p.facing_yaw << " noise " << p.noise_stddev << " variation "
    << p.variation << " transition " << p.transition << " seed " << p.seed << "\n";
  for (const auto& a : p.actions) {
    k << "action " << a.name << " " << static_cast<int>(a.kind) << " " << a.right_hand << " " << a.target_W.transpose()
      << " " << a.period << " " << a.amplitude << "\n";
  }
  return k.str();
}

}  // namespace

intent::SkeletonDataset RecordCellDemonstrations(const perception::SyntheticPersonParams& person) {
  return perception::RecordDemonstrations(person, kSubjects, kRepetitions, kSeconds, 30.0);
}

namespace {

perception::SyntheticPersonParams CellPerson(const std::string& perception_yaml) {
  perception::PerceptionSettings psettings;
  framework::ServiceFile(perception_yaml).ReadSection("perception", &psettings).Finish();
  return psettings.synthetic.Person();
}

}  // namespace

std::uint64_t CellPersonSeed(const std::string& perception_yaml) { return CellPerson(perception_yaml).seed; }

intent::SkeletonDataset RecordCellEpisodes(const std::string& perception_yaml, std::uint64_t seed, int people) {
  perception::SyntheticPersonParams person = CellPerson(perception_yaml);
  person.seed = seed;
  return perception::RecordEpisodes(person, people, kRepetitions, 2.0, 2.0, 30.0);
}

CellModelResult EnsureCellModel(const std::string& perception_yaml, const std::string& intent_yaml,
                                const std::string& fallback_dir, bool force) {
  // The person, as the perception service will simulate it.
  // Both files read and checked as their services read them.
  const perception::SyntheticPersonParams person = CellPerson(perception_yaml);
  // What the intent service expects.
  framework::ServiceFile iconf(intent_yaml);
  intent_service::IntentSettings isettings;
  iconf.ReadSection("intent", &isettings).Finish();
  const std::vector<std::string>& joints = isettings.joints;
  const double rate = isettings.rate_hz;
  const fs::path path = iconf.ResolvePath(isettings.model);
  const std::string key = ModelKey(person, joints, rate);

  CellModelResult result;
  for (const fs::path& candidate : {path, fs::path(fallback_dir) / path.filename()}) {
    if (!force && fs::exists(candidate) && ReadFile(candidate.string() + ".key") == key) {
      result.path = candidate.string();
      result.summary = "intent model " + result.path + " (cached; trained for this person)";
      return result;
    }
  }

  const auto t0 = std::chrono::steady_clock::now();
  // The actions one at a time, and the script as the cell plays it (its
  // transitions teach the belief filter that actions change).
  intent::SkeletonDataset data = RecordCellDemonstrations(person);
  if (!person.script.empty()) {
    intent::SkeletonDataset episodes = perception::RecordEpisodes(person, kSubjects, kRepetitions, 2.0, 2.0, 30.0);
    for (auto& s : episodes.sequences) data.sequences.push_back(std::move(s));
  }
  intent::IntentModelConfig config;
  // The configured joints, torso and hands defaulted among them (not among
  // the person's), so that any joint set of intent.yaml trains or is refused
  // with the joint named.
  intent::JointSelection selection;
  selection.joints = joints;
  try {
    config.joints = intent::ResolveJointConfig(data.joint_names, selection);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(intent_yaml + ": key 'intent.joints': " + e.what());
  }
  for (const auto& a : person.actions) {
    if (a.kind != perception::MotionKind::kRest) config.joints.objects.push_back(a.target_W);
  }
  config.rate = rate;
  intent::TrainParams params;
  params.seed = person.seed;
  const intent::IntentModel model = intent::TrainIntentModel(data, config, params, nullptr);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.trained = true;

  std::string first_error;
  for (const fs::path& candidate : {path, fs::path(fallback_dir) / path.filename()}) {
    try {
      fs::create_directories(candidate.parent_path());
      intent::SaveIntentModel(model, candidate.string());
      core::WriteFileAtomically(candidate.string() + ".key", key);
      result.path = candidate.string();
      break;
    } catch (const std::exception& e) {
      if (first_error.empty()) first_error = e.what();
    }
  }
  if (result.path.empty()) throw std::runtime_error("cannot write the intent model: " + first_error);
  std::ostringstream s;
  s.precision(3);
  s << "intent model trained in " << result.seconds << " s from " << data.sequences.size()
    << " demonstrations of the synthetic person (" << person.actions.size() << " actions), written to " << result.path;
  result.summary = s.str();
  return result;
}

}  // namespace iplan::cli
