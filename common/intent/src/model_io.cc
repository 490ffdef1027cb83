#include "iplan/intent/model_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "iplan/core/atomic_file.h"
#include "iplan/core/checksum.h"

namespace iplan::intent {
namespace {

constexpr char kMagic[8] = {'I', 'P', 'L', 'A', 'N', 'I', 'N', 'T'};

class Writer {
 public:
  template <typename T>
  void Pod(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    out_.append(b, sizeof(T));
  }
  void U64(std::uint64_t v) { Pod(v); }
  void I64(std::int64_t v) { Pod(v); }
  void F64(double v) { Pod(v); }
  void Str(const std::string& s) {
    U64(s.size());
    out_ += s;
  }
  void Mat(const Eigen::MatrixXd& m) {
    I64(m.rows());
    I64(m.cols());
    out_.append(reinterpret_cast<const char*>(m.data()), sizeof(double) * m.size());
  }
  void Vec(const Eigen::VectorXd& v) { Mat(v); }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  Reader(const char* data, size_t size, const std::string& source)
      : data_(data), size_(size), source_(source) {}
  template <typename T>
  T Pod() {
    Need(sizeof(T));
    T v;
    std::memcpy(&v, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::uint64_t U64() { return Pod<std::uint64_t>(); }
  std::int64_t I64() { return Pod<std::int64_t>(); }
  double F64() { return Pod<double>(); }
  std::string Str() {
    const std::uint64_t n = U64();
    Need(n);
    std::string s(data_ + pos_, n);
    pos_ += n;
    return s;
  }
  Eigen::MatrixXd Mat() {
    const std::int64_t r = I64(), c = I64();
    if (r < 0 || c < 0 || (r > 0 && c > static_cast<std::int64_t>(size_ / 8 / r + 1))) {
      Fail("bad matrix size " + std::to_string(r) + " x " + std::to_string(c));
    }
    Need(static_cast<size_t>(r * c) * sizeof(double));
    Eigen::MatrixXd m(r, c);
    std::memcpy(m.data(), data_ + pos_, sizeof(double) * r * c);
    pos_ += sizeof(double) * r * c;
    return m;
  }
  Eigen::VectorXd Vec() {
    const Eigen::MatrixXd m = Mat();
    if (m.cols() != 1 && m.size() != 0) Fail("expected a vector");
    return Eigen::Map<const Eigen::VectorXd>(m.data(), m.size());
  }
  bool AtEnd() const { return pos_ == size_; }
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(source_ + ": invalid intent model payload: " + what);
  }

 private:
  void Need(size_t n) const {
    if (n > size_ - pos_) Fail("truncated");
  }
  const char* data_;
  size_t size_;
  size_t pos_ = 0;
  std::string source_;
};

void WriteStrings(Writer* w, const std::vector<std::string>& v) {
  w->U64(v.size());
  for (const std::string& s : v) w->Str(s);
}
std::vector<std::string> ReadStrings(Reader* r) {
  const std::uint64_t n = r->U64();
  if (n > (1u << 20)) r->Fail("implausible string count");
  std::vector<std::string> v;
  for (std::uint64_t i = 0; i < n; ++i) v.push_back(r->Str());
  return v;
}

std::string JoinNames(const std::vector<std::string>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + v[i];
  return s + "]";
}

// The first difference between the model's and the configured joint lists,
// naming the joint.
std::string JointDifference(const std::vector<std::string>& model,
                            const std::vector<std::string>& configured) {
  for (const std::string& j : configured) {
    if (std::find(model.begin(), model.end(), j) == model.end()) {
      return "configured joint '" + j + "' is not a model joint";
    }
  }
  for (const std::string& j : model) {
    if (std::find(configured.begin(), configured.end(), j) == configured.end()) {
      return "model joint '" + j + "' is not configured";
    }
  }
  for (size_t i = 0; i < model.size() && i < configured.size(); ++i) {
    if (model[i] != configured[i]) {
      return "joint " + std::to_string(i + 1) + " is '" + model[i] + "' in the model but '" +
             configured[i] + "' in the configuration (same joints, other order)";
    }
  }
  return "a joint is listed twice";
}

}  // namespace

std::string SerializeIntentModel(const IntentModel& m) {
  Writer w;
  const IntentModelConfig& c = m.config;
  WriteStrings(&w, c.joints.joints);
  WriteStrings(&w, c.joints.torso);
  WriteStrings(&w, c.joints.hands);
  w.U64(c.joints.objects.size());
  for (const Eigen::Vector3d& o : c.joints.objects) w.Vec(o);
  w.F64(c.rate);
  w.I64(c.window);
  w.I64(c.horizon);
  w.I64(c.velocity_frames);
  w.I64(c.dtw_band);
  w.F64(c.sensor_noise_std);
  w.F64(c.features.torso_motion_weight);
  w.I64(c.features.normalise_body_size ? 1 : 0);
  w.I64(c.history_samples);  // version 4
  WriteStrings(&w, m.actions);
  w.F64(m.classifier.sigma);
  w.U64(m.classifier.import_windows.size());
  for (const Eigen::MatrixXd& iw : m.classifier.import_windows) w.Mat(iw);
  w.Mat(m.classifier.ivm.import_index.cast<double>());
  w.Mat(m.classifier.ivm.alpha);
  w.Vec(m.classifier.ivm.bias);
  w.F64(m.classifier.belief.time_constant);
  w.F64(m.classifier.belief.min_probability);
  w.I64(m.classifier.belief.motion_weighted ? 1 : 0);
  w.U64(m.forecasters.size());
  for (const ActionForecaster& f : m.forecasters) {
    w.Vec(f.input_mean);
    w.Vec(f.input_scale);
    w.Vec(f.output_mean);
    w.Vec(f.output_scale);
    w.I64(f.num_training_windows);
    const SparseGpHyper& h = f.gp.hyper();
    w.Mat(h.pseudo_inputs);
    w.Vec(h.log_lengthscales);
    w.F64(h.log_signal_variance);
    w.F64(h.log_noise_variance);
    w.Mat(f.gp.alpha());
    w.Mat(f.gp.cov_correction());
  }
  // Version 3: the forecast settings, last.
  w.I64(m.forecast.baseline.smoothing_frames);
  w.F64(m.forecast.baseline.damping_time_constant);
  w.F64(m.forecast.residual_weight);
  w.Vec(m.forecast.variance_scale);
  w.F64(m.forecast.motion_offset);
  w.Vec(m.forecast.reference_speed);
  const std::string payload = std::move(w.bytes());
  Writer header;
  header.bytes().append(kMagic, sizeof(kMagic));
  header.Pod<std::uint32_t>(kIntentModelFormatVersion);
  header.U64(payload.size());
  return core::SealChecksummed(header.bytes(), payload, core::ChecksumAt::kAfterPayload);
}

namespace {

// The checked payload of a model file and its format version: magic,
// version range, declared size and checksum.
std::uint32_t OpenPayload(const std::string& bytes, const std::string& source, std::size_t* size) {
  const size_t header = sizeof(kMagic) + 4 + 8;
  if (bytes.size() < header + 8 || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw std::runtime_error(source + ": not an iplan intent model file (bad magic or too short)");
  }
  Reader head(bytes.data() + sizeof(kMagic), 12, source);
  const std::uint32_t version = head.Pod<std::uint32_t>();
  if (version < kOldestReadableIntentModelFormatVersion || version > kIntentModelFormatVersion) {
    throw std::runtime_error(source + ": intent model format version " + std::to_string(version) +
                             ", but this build reads versions " +
                             std::to_string(kOldestReadableIntentModelFormatVersion) + " to " +
                             std::to_string(kIntentModelFormatVersion) + "; retrain the model");
  }
  const std::uint64_t declared = head.U64();
  if (declared != bytes.size() - header - 8) {
    throw std::runtime_error(source + ": intent model file is truncated or has trailing data (payload " +
                             std::to_string(declared) + " bytes declared, " +
                             std::to_string(bytes.size() - std::min(bytes.size(), header + 8)) +
                             " present)");
  }
  if (!core::OpenChecksummed(bytes, header, core::ChecksumAt::kAfterPayload)) {
    throw std::runtime_error(source + ": intent model checksum mismatch: the file is corrupt");
  }
  *size = declared;
  return version;
}

void ReadConfig(Reader* r, std::uint32_t version, IntentModelConfig* c) {
  c->joints.joints = ReadStrings(r);
  c->joints.torso = ReadStrings(r);
  c->joints.hands = ReadStrings(r);
  const std::uint64_t num_objects = r->U64();
  if (num_objects > 4096) r->Fail("implausible object count");
  for (std::uint64_t i = 0; i < num_objects; ++i) {
    const Eigen::VectorXd o = r->Vec();
    if (o.size() != 3) r->Fail("object position is not 3-D");
    c->joints.objects.push_back(o);
  }
  c->rate = r->F64();
  c->window = static_cast<int>(r->I64());
  c->horizon = static_cast<int>(r->I64());
  c->velocity_frames = static_cast<int>(r->I64());
  c->dtw_band = static_cast<int>(r->I64());
  c->sensor_noise_std = r->F64();
  c->features.torso_motion_weight = r->F64();
  c->features.normalise_body_size = r->I64() != 0;
  // Before version 4 the forecaster had no history inputs.
  c->history_samples = version >= 4 ? static_cast<int>(r->I64()) : 0;
  const std::string config_error = c->Validate();
  if (!config_error.empty()) r->Fail("configuration: " + config_error);
}

// The classifier; returns the number of forecasters that follow.
std::uint64_t ReadClassifier(Reader* r, const FeatureLayout& layout, IntentModel* m) {
  m->actions = ReadStrings(r);
  m->classifier.sigma = r->F64();
  const std::uint64_t q = r->U64();
  if (q > (1u << 20)) r->Fail("implausible import-vector count");
  for (std::uint64_t i = 0; i < q; ++i) m->classifier.import_windows.push_back(r->Mat());
  m->classifier.ivm.import_index = r->Mat().col(0).cast<int>();
  m->classifier.ivm.alpha = r->Mat();
  m->classifier.ivm.bias = r->Vec();
  m->classifier.belief.time_constant = r->F64();
  m->classifier.belief.min_probability = r->F64();
  m->classifier.belief.motion_weighted = r->I64() != 0;
  if (const std::string why = m->classifier.belief.Validate(); !why.empty()) r->Fail("belief filter: " + why);
  const std::uint64_t nf = r->U64();
  const Eigen::Index C = static_cast<Eigen::Index>(m->actions.size());
  if (nf != m->actions.size() || m->classifier.ivm.bias.size() != C ||
      m->classifier.ivm.alpha.rows() != static_cast<Eigen::Index>(q) ||
      m->classifier.ivm.alpha.cols() != C) {
    r->Fail("classifier sizes do not match the action count " + std::to_string(C));
  }
  for (const Eigen::MatrixXd& iw : m->classifier.import_windows) {
    if (iw.rows() != layout.frame_feature_size() || iw.cols() != m->config.window) {
      r->Fail("import window size does not match the configuration");
    }
  }
  return nf;
}

ActionForecaster ReadForecaster(Reader* r, const FeatureLayout& layout, int history_samples, Eigen::Index P,
                                std::uint64_t i) {
  ActionForecaster f;
  f.input_mean = r->Vec();
  f.input_scale = r->Vec();
  f.output_mean = r->Vec();
  f.output_scale = r->Vec();
  f.num_training_windows = static_cast<int>(r->I64());
  SparseGpHyper h;
  h.pseudo_inputs = r->Mat();
  h.log_lengthscales = r->Vec();
  h.log_signal_variance = r->F64();
  h.log_noise_variance = r->F64();
  Eigen::MatrixXd alpha = r->Mat();
  Eigen::MatrixXd corr = r->Mat();
  if (f.input_mean.size() != layout.forecast_input_size(history_samples) || f.input_scale.size() != f.input_mean.size() ||
      f.output_mean.size() != P || f.output_scale.size() != P || h.pseudo_inputs.cols() != f.input_mean.size() ||
      alpha.cols() != P) {
    r->Fail("forecaster " + std::to_string(i) + " sizes do not match the configuration");
  }
  try {
    f.gp = SparseGp::FromParts(std::move(h), std::move(alpha), std::move(corr));
  } catch (const std::invalid_argument& e) {
    r->Fail(e.what());
  }
  return f;
}

void ReadForecastSettings(Reader* r, std::uint32_t version, ForecastSettings* s) {
  if (version >= 3) {
    s->baseline.smoothing_frames = static_cast<int>(r->I64());
    s->baseline.damping_time_constant = r->F64();
    s->residual_weight = r->F64();
    s->variance_scale = r->Vec();
    s->motion_offset = r->F64();
    s->reference_speed = r->Vec();
  } else {
    // Version 2 forecasters predict the displacement from the current pose,
    // uncalibrated: exactly L = 1 (the newest frame, no velocity), w = 1,
    // s = 1, no activity scaling.
    *s = ForecastSettings{};
    s->baseline = KinematicBaseline{1, 0.0};
    s->residual_weight = 1.0;
  }
}

}  // namespace

IntentModel DeserializeIntentModel(const std::string& bytes, const std::string& source) {
  std::size_t size = 0;
  const std::uint32_t version = OpenPayload(bytes, source, &size);
  Reader r(bytes.data() + sizeof(kMagic) + 4 + 8, size, source);
  IntentModel m;
  ReadConfig(&r, version, &m.config);
  const IntentModelConfig& c = m.config;
  const FeatureLayout layout(c.joints, c.features);
  const std::uint64_t nf = ReadClassifier(&r, layout, &m);
  const Eigen::Index P = static_cast<Eigen::Index>(c.horizon) * 3 * layout.num_joints();
  for (std::uint64_t i = 0; i < nf; ++i) {
    m.forecasters.push_back(ReadForecaster(&r, layout, c.history_samples, P, i));
  }
  ReadForecastSettings(&r, version, &m.forecast);
  if (const std::string why = m.forecast.Validate(c.horizon, layout.num_joints()); !why.empty()) {
    r.Fail("forecast settings: " + why);
  }
  if (!r.AtEnd()) r.Fail("trailing bytes after the forecast settings");
  return m;
}

void SaveIntentModel(const IntentModel& model, const std::string& path) {
  core::WriteFileAtomically(path, SerializeIntentModel(model));
}

IntentModel LoadIntentModel(const std::string& path, const ModelExpectation& expected) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open intent model file");
  std::ostringstream ss;
  ss << in.rdbuf();
  IntentModel m = DeserializeIntentModel(ss.str(), path);
  if (!expected.joints.empty() && expected.joints != m.config.joints.joints) {
    throw std::runtime_error(path + ": model joints " + JoinNames(m.config.joints.joints) +
                             " do not match the configured joints " + JoinNames(expected.joints) +
                             ": " + JointDifference(m.config.joints.joints, expected.joints));
  }
  if (expected.rate.has_value() &&
      std::abs(*expected.rate - m.config.rate) > 1e-9 * std::abs(*expected.rate)) {
    std::ostringstream msg;
    msg << path << ": model rate " << m.config.rate << " Hz does not match the configured rate "
        << *expected.rate << " Hz";
    throw std::runtime_error(msg.str());
  }
  return m;
}

}  // namespace iplan::intent
