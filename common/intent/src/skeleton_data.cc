#include "iplan/intent/skeleton_data.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace iplan::intent {
namespace {

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  for (char ch : line) {
    if (ch == ',') {
      fields.push_back(field);
      field.clear();
    } else if (ch != '\r') {
      field.push_back(ch);
    }
  }
  fields.push_back(field);
  return fields;
}

[[noreturn]] void ThrowAt(const std::string& path, long line,
                          const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

double ParseNumber(const std::string& text, const std::string& path, long line,
                   const std::string& column) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size() || errno == ERANGE ||
      !std::isfinite(value)) {
    ThrowAt(path, line,
            "column '" + column + "': '" + text + "' is not a finite number");
  }
  return value;
}

// The leading columns of the shared CSV layout, before the joint triples.
const std::vector<std::string>& LeadColumns() {
  static const std::vector<std::string> lead = {"sequence", "subject", "action",
                                                "frame", "time"};
  return lead;
}

// Checks the header line (split into `header`) and returns the joint names
// of its "<joint>.x,<joint>.y,<joint>.z" triples.
std::vector<std::string> ParseHeader(const std::vector<std::string>& header,
                                     const std::string& path) {
  const std::vector<std::string>& lead = LeadColumns();
  if (header.size() < lead.size() + 3) {
    ThrowAt(path, 1, "header has " + std::to_string(header.size()) +
                         " columns; expected sequence,subject,action,frame,"
                         "time followed by at least one joint triple");
  }
  for (size_t i = 0; i < lead.size(); ++i) {
    if (header[i] != lead[i]) {
      ThrowAt(path, 1, "header column " + std::to_string(i + 1) + " is '" +
                           header[i] + "', expected '" + lead[i] + "'");
    }
  }
  if ((header.size() - lead.size()) % 3 != 0) {
    ThrowAt(path, 1, "joint columns are not x,y,z triples (" +
                         std::to_string(header.size() - lead.size()) +
                         " joint columns)");
  }
  std::vector<std::string> joint_names;
  const char* axes[3] = {".x", ".y", ".z"};
  for (size_t c = lead.size(); c < header.size(); c += 3) {
    const std::string& first = header[c];
    if (first.size() < 3 || first.compare(first.size() - 2, 2, ".x") != 0) {
      ThrowAt(path, 1, "column '" + first + "' should be '<joint>.x'");
    }
    const std::string name = first.substr(0, first.size() - 2);
    for (int a = 0; a < 3; ++a) {
      if (header[c + a] != name + axes[a]) {
        ThrowAt(path, 1, "column '" + header[c + a] + "' should be '" + name +
                             axes[a] + "'");
      }
    }
    joint_names.push_back(name);
  }
  return joint_names;
}

// One sequence while its rows are read.
struct Builder {
  SkeletonSequence seq;
  std::vector<double> time;
  std::vector<double> values;
};

// The sequences of the rows read so far; rows of one sequence are contiguous.
struct RowReader {
  const std::string& path;
  const std::vector<std::string>& header;
  std::vector<Builder> builders;
  std::set<std::string> finished;

  // The builder of the sequence of row `f` (line `line_no`), a new one at
  // the first row of a sequence.
  Builder& SequenceOf(const std::vector<std::string>& f, long line_no) {
    if (f[0].empty()) ThrowAt(path, line_no, "empty sequence id");
    if (builders.empty() || builders.back().seq.id != f[0]) {
      if (!builders.empty()) finished.insert(builders.back().seq.id);
      if (finished.count(f[0]) != 0) {
        ThrowAt(path, line_no,
                "rows of sequence '" + f[0] + "' are not contiguous");
      }
      builders.emplace_back();
      builders.back().seq.id = f[0];
      builders.back().seq.subject = f[1];
      builders.back().seq.action = f[2];
    }
    Builder& b = builders.back();
    if (f[1] != b.seq.subject || f[2] != b.seq.action) {
      ThrowAt(path, line_no,
              "sequence '" + f[0] + "' changes subject or action mid-way ('" +
                  f[1] + "', '" + f[2] + "')");
    }
    return b;
  }

  void AddRow(const std::string& line, long line_no) {
    const std::vector<std::string> f = SplitCsvLine(line);
    if (f.size() != header.size()) {
      ThrowAt(path, line_no, "row has " + std::to_string(f.size()) +
                                 " fields, header has " +
                                 std::to_string(header.size()));
    }
    Builder& b = SequenceOf(f, line_no);
    ParseNumber(f[3], path, line_no, "frame");
    const double t = ParseNumber(f[4], path, line_no, "time");
    if (!b.time.empty() && !(t > b.time.back())) {
      ThrowAt(path, line_no,
              "time " + f[4] + " does not increase within sequence '" + f[0] +
                  "'");
    }
    b.time.push_back(t);
    for (size_t c = LeadColumns().size(); c < f.size(); ++c) {
      // A joint the tracker did not detect may be written as nan or left empty.
      if (f[c].empty() || f[c] == "nan" || f[c] == "NaN" || f[c] == "-nan") {
        b.values.push_back(std::numeric_limits<double>::quiet_NaN());
      } else {
        b.values.push_back(ParseNumber(f[c], path, line_no, header[c]));
      }
    }
  }
};

}  // namespace

SkeletonDataset LoadSkeletonCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::string line;
  long line_no = 1;
  if (!std::getline(in, line)) ThrowAt(path, 1, "empty file (no header)");
  const std::vector<std::string> header = SplitCsvLine(line);
  SkeletonDataset data;
  data.joint_names = ParseHeader(header, path);
  const int num_joints = static_cast<int>(data.joint_names.size());

  RowReader rows{path, header, {}, {}};
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    rows.AddRow(line, line_no);
  }
  if (rows.builders.empty()) ThrowAt(path, line_no, "no data rows");
  for (Builder& b : rows.builders) {
    const int n = static_cast<int>(b.time.size());
    b.seq.time = Eigen::Map<Eigen::VectorXd>(b.time.data(), n);
    b.seq.positions = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic,
                                               Eigen::Dynamic, Eigen::RowMajor>>(
        b.values.data(), n, 3 * num_joints);
    data.sequences.push_back(std::move(b.seq));
  }
  return data;
}

bool JointDetected(const Eigen::Ref<const Eigen::RowVectorXd>& p) {
  return p.allFinite() && !(p.array() == 0.0).all();
}

SkeletonDataset SelectSubjects(const SkeletonDataset& data,
                               const std::vector<std::string>& subjects) {
  SkeletonDataset out;
  out.joint_names = data.joint_names;
  const std::set<std::string> wanted(subjects.begin(), subjects.end());
  std::set<std::string> seen;
  for (const SkeletonSequence& s : data.sequences) {
    if (wanted.count(s.subject) != 0) {
      out.sequences.push_back(s);
      seen.insert(s.subject);
    }
  }
  for (const std::string& s : subjects) {
    if (seen.count(s) == 0) {
      std::set<std::string> all;
      for (const SkeletonSequence& q : data.sequences) all.insert(q.subject);
      std::string list;
      for (const std::string& a : all) list += (list.empty() ? "" : ",") + a;
      throw std::invalid_argument("subject '" + s +
                                  "' has no sequence in the data (subjects: " +
                                  list + ")");
    }
  }
  return out;
}

std::vector<int> JointIndices(const std::vector<std::string>& joint_names,
                              const std::vector<std::string>& names) {
  std::vector<int> index;
  for (const std::string& n : names) {
    int found = -1;
    for (size_t j = 0; j < joint_names.size(); ++j) {
      if (joint_names[j] == n) found = static_cast<int>(j);
    }
    if (found < 0) {
      std::string list;
      for (const std::string& a : joint_names) list += (list.empty() ? "" : ",") + a;
      throw std::invalid_argument("unknown joint '" + n + "' (available: " +
                                  list + ")");
    }
    index.push_back(found);
  }
  return index;
}

const std::string& ActionAt(const Track& track, int row) {
  return track.frame_actions.empty() ? track.action : track.frame_actions.at(static_cast<size_t>(row));
}

std::vector<Track> ResampleSequence(const SkeletonSequence& sequence,
                                    const std::vector<int>& joint_index,
                                    double rate, double max_gap) {
  if (!(rate > 0.0) || !(max_gap > 0.0)) {
    throw std::invalid_argument("ResampleSequence: rate " +
                                std::to_string(rate) + " and max_gap " +
                                std::to_string(max_gap) + " must be positive");
  }
  const int num_out = static_cast<int>(joint_index.size());
  const bool has_reaching = sequence.reaching.size() > 0;
  if (has_reaching && (sequence.reaching.rows() != sequence.time.size() ||
                       sequence.reaching.cols() * 3 != sequence.positions.cols())) {
    throw std::invalid_argument("ResampleSequence: sequence " + sequence.id + " has reaching flags of " +
                                std::to_string(sequence.reaching.rows()) + " x " +
                                std::to_string(sequence.reaching.cols()) + ", not frames x joints");
  }
  const bool has_actions = !sequence.frame_actions.empty();
  if (has_actions && static_cast<Eigen::Index>(sequence.frame_actions.size()) != sequence.time.size()) {
    throw std::invalid_argument("ResampleSequence: sequence " + sequence.id + " has " +
                                std::to_string(sequence.frame_actions.size()) + " frame actions for " +
                                std::to_string(sequence.time.size()) + " frames");
  }
  // Frames where every selected joint was detected.
  std::vector<int> valid;
  for (int i = 0; i < sequence.time.size(); ++i) {
    bool ok = true;
    for (int j : joint_index) {
      if (!JointDetected(sequence.positions.block<1, 3>(i, 3 * j))) ok = false;
    }
    if (ok) valid.push_back(i);
  }
  const int n = static_cast<int>(valid.size());
  auto time_of = [&](int v) { return sequence.time(valid[v]); };
  std::vector<Track> tracks;
  // Split at long gaps.
  int begin = 0;
  int part = 0;
  while (begin < n) {
    int end = begin + 1;
    while (end < n && time_of(end) - time_of(end - 1) <= max_gap) ++end;
    const double t0 = time_of(begin);
    const double t1 = time_of(end - 1);
    const int count = static_cast<int>(std::floor((t1 - t0) * rate + 1e-9)) + 1;
    Track track;
    track.sequence_id =
        part == 0 ? sequence.id : sequence.id + "#" + std::to_string(part);
    track.subject = sequence.subject;
    track.action = sequence.action;
    track.positions.resize(count, 3 * num_out);
    if (has_reaching) track.reaching.resize(count, num_out);
    if (has_actions) track.frame_actions.resize(count);
    int k = begin;
    for (int i = 0; i < count; ++i) {
      const double t = t0 + i / rate;
      while (k + 1 < end - 1 && time_of(k + 1) <= t) ++k;
      const int k1 = std::min(k + 1, end - 1);
      double u = 0.0;
      if (k1 != k) u = std::clamp((t - time_of(k)) / (time_of(k1) - time_of(k)), 0.0, 1.0);
      for (int j = 0; j < num_out; ++j) {
        const int c = 3 * joint_index[j];
        track.positions.block<1, 3>(i, 3 * j) =
            (1.0 - u) * sequence.positions.block<1, 3>(valid[k], c) +
            u * sequence.positions.block<1, 3>(valid[k1], c);
        if (has_reaching) track.reaching(i, j) = sequence.reaching(valid[u < 0.5 ? k : k1], joint_index[j]);
      }
      if (has_actions) track.frame_actions[i] = sequence.frame_actions[valid[u < 0.5 ? k : k1]];
    }
    tracks.push_back(std::move(track));
    begin = end;
    ++part;
  }
  return tracks;
}

}  // namespace iplan::intent
