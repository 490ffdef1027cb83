#include "task_planner.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "iplan/core/atomic_file.h"
#include "iplan/core/checksum.h"
#include "iplan/core/params.h"

namespace iplan::supervisor {
namespace {

// Version 2 adds the number of learning episodes after the row count;
// version 3 then the learned task durations (per task: outcomes observed,
// their mean in s). Tables of versions 1 and 2 still load (0 episodes, no
// durations).
constexpr char kMagic[8] = {'I', 'P', 'L', 'Q', 'T', 'B', 'L', '3'};
constexpr char kMagicV2[8] = {'I', 'P', 'L', 'Q', 'T', 'B', 'L', '2'};
constexpr char kMagicV1[8] = {'I', 'P', 'L', 'Q', 'T', 'B', 'L', '1'};

template <class T>
void Put(std::string* out, const T& v) {
  out->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
bool Get(const std::string& in, std::size_t* pos, T* v) {
  if (*pos + sizeof(T) > in.size()) return false;
  std::memcpy(v, in.data() + *pos, sizeof(T));
  *pos += sizeof(T);
  return true;
}

}  // namespace

std::string ToolPose::Validate() const {
  auto finite = [](const std::vector<double>& v) { return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }); };
  if (!position.empty() && (position.size() != 3 || !finite(position))) return "position must be 3 finite numbers (m)";
  if (z_axis.size() != 3 || !finite(z_axis) || std::hypot(z_axis[0], z_axis[1], z_axis[2]) < 1e-9)
    return "z_axis must be 3 finite numbers, not all 0";
  return "";
}

std::string TaskGraph::Validate() const {
  if (tasks.empty()) return "no robot tasks";
  if (tasks.size() > 63) return "at most 63 robot tasks";
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (tasks[i].name == tasks[j].name) return "task '" + tasks[i].name + "' defined twice";
    }
    const RobotTask& t = tasks[i];
    if (t.goal.empty() && !t.goal_pose.given()) return "task '" + t.name + "' has no goal (give goal or goal_pose)";
    for (const auto& [key, pose] : {std::pair{"goal_pose", &t.goal_pose}, std::pair{"retreat_pose", &t.retreat_pose}}) {
      if (const std::string why = pose->Validate(); !why.empty()) return "task '" + t.name + "': " + key + ": " + why;
    }
    if (!t.retreat.empty() && !t.goal.empty() && t.retreat.size() != t.goal.size()) {
      return "task '" + tasks[i].name + "' has a retreat of " + std::to_string(tasks[i].retreat.size()) +
             " joint positions and a goal of " + std::to_string(tasks[i].goal.size());
    }
    for (double v : tasks[i].goal) {
      if (!std::isfinite(v)) return "task '" + tasks[i].name + "' has a non-finite goal";
    }
    for (double v : tasks[i].retreat) {
      if (!std::isfinite(v)) return "task '" + tasks[i].name + "' has a non-finite retreat";
    }
    for (const auto& a : tasks[i].after) {
      if (std::none_of(tasks.begin(), tasks.end(), [&](const RobotTask& t) { return t.name == a; })) {
        return "task '" + tasks[i].name + "' comes after unknown task '" + a + "'";
      }
    }
    for (const auto& c : tasks[i].conflicts_with) {
      if (std::find(human_actions.begin(), human_actions.end(), c) == human_actions.end()) {
        return "task '" + tasks[i].name + "' conflicts with unknown human action '" + c + "'";
      }
    }
  }
  if (!rest.empty() && std::none_of(tasks.begin(), tasks.end(), [&](const RobotTask& t) { return t.name == rest; }))
    return "rest names unknown task '" + rest + "'";
  if (const std::string why = human_graph.Validate(human_actions); !why.empty()) return why;
  // Cycles: repeatedly finish tasks whose predecessors are finished.
  std::vector<bool> done(tasks.size(), false);
  for (std::size_t round = 0; round < tasks.size(); ++round) {
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      if (done[i]) continue;
      bool ready = true;
      for (const auto& a : tasks[i].after) {
        for (std::size_t j = 0; j < tasks.size(); ++j) {
          if (tasks[j].name == a && !done[j]) ready = false;
        }
      }
      if (ready) done[i] = true;
    }
  }
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (!done[i]) return "the precedence of task '" + tasks[i].name + "' has a cycle";
  }
  return "";
}

TaskGraph LoadTaskGraph(const std::string& path) {
  return core::LoadParamsFile<TaskGraph>(path, {}, core::ConfigSection::EmptyFile::kError);
}

std::string QLearningParams::Validate() const {
  if (!(alpha > 0 && alpha <= 1)) return "alpha must be in (0, 1]";
  if (!(gamma >= 0 && gamma < 1)) return "gamma must be in [0, 1)";
  if (!(epsilon >= 0 && epsilon <= 1)) return "epsilon must be in [0, 1]";
  if (!(epsilon_decay > 0 && epsilon_decay <= 1)) return "epsilon_decay must be in (0, 1]";
  if (!(epsilon_min >= 0 && epsilon_min <= 1)) return "epsilon_min must be in [0, 1]";
  if (!(delay_weight >= 0)) return "delay_weight must be >= 0";
  if (!(duration_weight >= 0) || !std::isfinite(duration_weight)) return "duration_weight must be >= 0";
  if (!(travel_weight >= 0) || !std::isfinite(travel_weight)) return "travel_weight must be >= 0";
  if (!(travel_speed > 0) || !std::isfinite(travel_speed)) return "travel_speed must be > 0";
  if (!(anticipation_weight >= 0) || !std::isfinite(anticipation_weight)) return "anticipation_weight must be >= 0";
  if (!(task_duration_prior > 0) || !std::isfinite(task_duration_prior)) return "task_duration_prior must be > 0";
  if (anticipation_depth < 1 || anticipation_depth > 8) return "anticipation_depth must be in [1, 8]";
  return "";
}

TaskPlanner::TaskPlanner(TaskGraph graph, QLearningParams params)
    : graph_(std::move(graph)), params_(params), rng_(params.seed) {
  if (const std::string why = graph_.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  for (const auto& t : graph_.tasks) {
    uint64_t mask = 0;
    for (const auto& a : t.after) {
      for (std::size_t j = 0; j < graph_.tasks.size(); ++j) {
        if (graph_.tasks[j].name == a) mask |= 1ULL << j;
      }
    }
    prerequisites_.push_back(mask);
  }
  for (std::size_t i = 0; i < graph_.tasks.size(); ++i) {
    if (graph_.tasks[i].name == graph_.rest) rest_ = static_cast<int>(i);
  }
  durations_.assign(graph_.tasks.size(), {0, 0.0});
}

bool TaskPlanner::episode_done() const { return state_ == (1ULL << graph_.tasks.size()) - 1; }

std::vector<int> TaskPlanner::Available() const { return AvailableIn(state_); }

std::vector<int> TaskPlanner::AvailableIn(State state) const {
  std::vector<int> out;
  for (std::size_t i = 0; i < graph_.tasks.size(); ++i) {
    const uint64_t bit = 1ULL << i;
    if (!(state & bit) && (state & prerequisites_[i]) == prerequisites_[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

double TaskPlanner::Harmony(int task, const std::map<std::string, double>& belief) const {
  double conflict = 0;
  for (const auto& c : graph_.tasks[static_cast<std::size_t>(task)].conflicts_with) {
    const auto it = belief.find(c);
    if (it != belief.end()) conflict += it->second;
  }
  return 1.0 - std::clamp(conflict, 0.0, 1.0);
}

std::vector<double>& TaskPlanner::Row(State s) {
  auto it = q_.find(s);
  if (it == q_.end()) it = q_.emplace(s, std::vector<double>(graph_.tasks.size(), 0.0)).first;
  return it->second;
}

const std::vector<double>* TaskPlanner::PlaceAfter(int task) const {
  if (task >= 0) {
    const RobotTask& t = graph_.tasks[static_cast<std::size_t>(task)];
    return t.retreat.empty() ? &t.goal : &t.retreat;
  }
  return rest_ >= 0 ? &graph_.tasks[static_cast<std::size_t>(rest_)].goal : nullptr;
}

double TaskPlanner::TravelBetween(int from_task, int task) const {
  const std::vector<double>* from = PlaceAfter(from_task);
  const std::vector<double>& to = graph_.tasks[static_cast<std::size_t>(task)].goal;
  if (!from || from->empty() || from->size() != to.size()) return 0.0;
  double largest = 0.0;
  for (std::size_t j = 0; j < to.size(); ++j) largest = std::max(largest, std::abs(to[j] - (*from)[j]));
  return largest / params_.travel_speed;
}

double TaskPlanner::Travel(int task) const { return TravelBetween(last_, task); }

double TaskPlanner::Q(State s, int task) const {
  const auto it = q_.find(s);
  return it == q_.end() ? 0.0 : it->second[static_cast<std::size_t>(task)];
}

double TaskPlanner::Epsilon() const {
  if (!params_.learning) return 0.0;
  const double decayed = params_.epsilon * std::pow(params_.epsilon_decay, static_cast<double>(episodes_learned_));
  return std::min(params_.epsilon, std::max(params_.epsilon_min, decayed));
}

double TaskPlanner::TaskDuration(int task) const {
  const auto& [count, mean] = durations_[static_cast<std::size_t>(task)];
  return count > 0 ? mean : params_.task_duration_prior;
}

void TaskPlanner::ObserveDuration(int task, double seconds) {
  if (!(seconds > 0) || !std::isfinite(seconds)) return;
  auto& [count, mean] = durations_[static_cast<std::size_t>(task)];
  ++count;
  mean += (seconds - mean) / static_cast<double>(count);
}

double TaskPlanner::ExpectedConflict(int task, const ActionForecast& forecast, double from) const {
  const RobotTask& t = graph_.tasks[static_cast<std::size_t>(task)];
  std::vector<double> conflict(forecast.actions.size(), 0.0);
  for (std::size_t c = 0; c < forecast.actions.size(); ++c) {
    if (std::find(t.conflicts_with.begin(), t.conflicts_with.end(), forecast.actions[c]) != t.conflicts_with.end()) {
      conflict[c] = 1.0;
    }
  }
  const double to = from + TaskDuration(task);
  double seconds = 0;
  // Step k covers [k dt, (k + 1) dt); the part of it inside [from, to).
  for (std::size_t k = static_cast<std::size_t>(std::max(0.0, std::floor(from / forecast.dt))); k < forecast.p.size(); ++k) {
    const double begin = std::max(from, static_cast<double>(k) * forecast.dt);
    const double end = std::min(to, static_cast<double>(k + 1) * forecast.dt);
    if (end <= begin) {
      if (begin >= to) break;
      continue;
    }
    double p = 0;
    for (std::size_t c = 0; c < conflict.size(); ++c) p += forecast.p[k][c] * conflict[c];
    seconds += (end - begin) * std::clamp(p, 0.0, 1.0);
  }
  return seconds;
}

double TaskPlanner::OrderCost(State state, const ActionForecast* forecast, double from, int place, int task, int depth,
                              double conflict_weight, double travel_weight) const {
  double c = BestContinuation(state | (1ULL << task), forecast, from + TaskDuration(task), task, depth - 1,
                              conflict_weight, travel_weight);
  if (forecast && conflict_weight > 0) c += conflict_weight * ExpectedConflict(task, *forecast, from);
  if (travel_weight > 0) c += travel_weight * TravelBetween(place, task);
  return c;
}

double TaskPlanner::BestContinuation(State state, const ActionForecast* forecast, double from, int place, int depth,
                                     double conflict_weight, double travel_weight) const {
  if (depth <= 0) return 0.0;
  double best = 0;
  bool any = false;
  for (int b : AvailableIn(state)) {
    const double c = OrderCost(state, forecast, from, place, b, depth, conflict_weight, travel_weight);
    best = any ? std::min(best, c) : c;
    any = true;
  }
  return best;
}

ActionForecast TaskPlanner::SequenceForecast(State state, const ActionOutlook& outlook) const {
  // Long enough for the anticipation_depth longest tasks left.
  std::vector<double> left;
  for (std::size_t i = 0; i < graph_.tasks.size(); ++i) {
    if (!(state & (1ULL << i))) left.push_back(TaskDuration(static_cast<int>(i)));
  }
  std::sort(left.rbegin(), left.rend());
  double horizon = 0;
  for (std::size_t i = 0; i < left.size() && i < static_cast<std::size_t>(params_.anticipation_depth); ++i) horizon += left[i];
  return ForecastActions(graph_.human_graph, outlook, kForecastStep, static_cast<int>(std::ceil(horizon / kForecastStep)));
}

double TaskPlanner::ExpectedConflict(int task, const ActionOutlook& outlook) const {
  if (outlook.belief.empty()) return 0.0;
  const int steps = static_cast<int>(std::ceil(TaskDuration(task) / kForecastStep));
  return ExpectedConflict(task, ForecastActions(graph_.human_graph, outlook, kForecastStep, steps), 0.0);
}

double TaskPlanner::AnticipatedConflict(int task, const ActionOutlook& outlook) const {
  if (outlook.belief.empty()) return 0.0;
  const ActionForecast forecast = SequenceForecast(state_, outlook);
  return OrderCost(state_, &forecast, 0.0, last_, task, params_.anticipation_depth, 1.0, 0.0);
}

int TaskPlanner::Choose(const ActionOutlook& outlook) {
  const std::vector<int> avail = Available();
  if (avail.empty()) return -1;
  if (params_.learning && std::uniform_real_distribution<double>(0, 1)(rng_) < Epsilon()) {
    return avail[std::uniform_int_distribution<std::size_t>(0, avail.size() - 1)(rng_)];
  }
  // The anticipation (one forecast, as long as the longest sequence) and
  // the travel, of the candidate and of the continuation after it that
  // costs the least of both.
  const double w_c = outlook.belief.empty() ? 0.0 : params_.anticipation_weight;
  const double w_v = params_.travel_weight;
  std::optional<ActionForecast> forecast;
  if (w_c > 0) forecast = SequenceForecast(state_, outlook);
  std::vector<double> cost(graph_.tasks.size(), 0.0);
  if (w_c > 0 || w_v > 0) {
    for (int a : avail) {
      cost[static_cast<std::size_t>(a)] =
          OrderCost(state_, forecast ? &*forecast : nullptr, 0.0, last_, a, params_.anticipation_depth, w_c, w_v);
    }
  }
  auto score = [&](int a) { return Q(state_, a) - cost[static_cast<std::size_t>(a)]; };
  int best = avail.front();
  for (int a : avail) {
    const double qa = score(a), qb = score(best);
    if (qa > qb + 1e-12 ||
        (std::abs(qa - qb) <= 1e-12 && Harmony(a, outlook.belief) > Harmony(best, outlook.belief))) {
      best = a;
    }
  }
  return best;
}

double TaskPlanner::Complete(int task, bool succeeded, double delay, const std::map<std::string, double>& belief,
                             double motion) {
  const State s = state_;
  const State next = succeeded ? (s | (1ULL << task)) : s;
  // A time that is not a number says nothing about the task: learn
  // nothing from it, but the task did end, so the state still moves on.
  const bool refused = !std::isfinite(delay) || !std::isfinite(motion);
  const double reward = refused ? std::numeric_limits<double>::quiet_NaN()
                                : Harmony(task, belief) - params_.delay_weight * std::clamp(delay, 0.0, kMaxDelay) -
                                      params_.duration_weight * std::clamp(motion, 0.0, kMaxDelay);
  if (refused) ++refused_outcomes_;
  if (params_.learning && !refused) {
    double best_next = 0;
    bool any = false;
    for (std::size_t i = 0; i < graph_.tasks.size(); ++i) {
      const uint64_t bit = 1ULL << i;
      if (!(next & bit) && (next & prerequisites_[i]) == prerequisites_[i]) {
        const double q = Q(next, static_cast<int>(i));
        best_next = any ? std::max(best_next, q) : q;
        any = true;
      }
    }
    double& q = Row(s)[static_cast<std::size_t>(task)];
    // Bounded rewards keep Q bounded by |r| / (1 - gamma); only an absurd
    // delay_weight could still overflow it, and an inf in the table would
    // make every later save unloadable: keep the old value then.
    const double updated = q + params_.alpha * (reward + params_.gamma * best_next - q);
    if (std::isfinite(updated)) {
      q = updated;
    } else {
      ++refused_outcomes_;
    }
  }
  state_ = next;
  if (succeeded) {
    last_ = task;
    ObserveDuration(task, motion);
  }
  if (params_.learning && succeeded && episode_done()) ++episodes_learned_;
  return reward;
}

uint64_t TaskPlanner::GraphHash() const {
  uint64_t h = core::Fnv1a64("graph", core::kIplanFnvSeed);
  for (const auto& t : graph_.tasks) {
    h = core::Fnv1a64(t.name, h);
    for (const auto& a : t.after) h = core::Fnv1a64(a, h);
  }
  return h;
}

void TaskPlanner::Save(const std::string& path) {
  try {
    Write(path);
  } catch (const std::exception& e) {
    ++save_failures_;
    last_save_error_ = e.what();
    throw;
  }
}

void TaskPlanner::Write(const std::string& path) const {
  std::string body;
  Put(&body, GraphHash());
  Put(&body, static_cast<uint64_t>(graph_.tasks.size()));
  Put(&body, static_cast<uint64_t>(q_.size()));
  Put(&body, episodes_learned_);
  for (const auto& [count, mean] : durations_) {
    Put(&body, count);
    Put(&body, mean);
  }
  for (const auto& [s, row] : q_) {
    Put(&body, s);
    for (double v : row) Put(&body, v);
  }
  // Keep the previous good table: if the new one is ever damaged, the
  // loader falls back to it. Only a file that passes Load's checks becomes
  // the backup: after Load refused a corrupt main file and used the backup,
  // rotating blindly would copy the corrupt bytes over the one good copy.
  if (std::ifstream(path).good()) {
    const std::string previous = core::ReadFile(path);
    Table unused;
    if (!Parse(previous, path, &unused)) core::WriteFileAtomically(path + ".bak", previous);
  }
  core::WriteChecksummedFileAtomically(path, std::string_view(kMagic, sizeof(kMagic)), body,
                                      core::ChecksumAt::kBeforePayload);
}

std::optional<std::string> TaskPlanner::TryLoad(const std::string& path) {
  std::string data;
  try {
    data = core::ReadFile(path);
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  Table table;
  if (auto error = Parse(data, path, &table)) return error;
  q_ = std::move(table.q);
  episodes_learned_ = table.episodes;
  durations_.assign(graph_.tasks.size(), {0, 0.0});
  if (!table.durations.empty()) durations_ = std::move(table.durations);
  return std::nullopt;
}

std::optional<std::string> TaskPlanner::Parse(const std::string& data, const std::string& path, Table* out) const {
  if (data.size() < sizeof(kMagic) + 8) return path + " is not an iplan Q-table";
  int version = 0;
  for (const auto& [magic, v] : {std::pair{kMagicV1, 1}, std::pair{kMagicV2, 2}, std::pair{kMagic, 3}}) {
    if (std::memcmp(data.data(), magic, sizeof(kMagic)) == 0) version = v;
  }
  if (version == 0) return path + " is not an iplan Q-table";
  std::size_t pos = sizeof(kMagic);
  uint64_t hash = 0, ntasks = 0, nrows = 0;
  if (!core::OpenChecksummed(data, sizeof(kMagic), core::ChecksumAt::kBeforePayload)) {
    return path + " is corrupt (checksum mismatch)";
  }
  pos += sizeof(uint64_t);  // the checksum
  Table table;
  if (!Get(data, &pos, &hash) || !Get(data, &pos, &ntasks) || !Get(data, &pos, &nrows) ||
      (version >= 2 && !Get(data, &pos, &table.episodes))) {
    return path + " is truncated";
  }
  if (hash != GraphHash() || ntasks != graph_.tasks.size()) return path + " belongs to another task graph";
  if (version >= 3) {
    table.durations.resize(ntasks);
    for (std::size_t i = 0; i < ntasks; ++i) {
      auto& [count, mean] = table.durations[i];
      if (!Get(data, &pos, &count) || !Get(data, &pos, &mean)) return path + " is truncated";
      if (!std::isfinite(mean) || mean < 0) {
        return path + " has an impossible duration of task '" + graph_.tasks[i].name + "'";
      }
    }
  }
  for (uint64_t r = 0; r < nrows; ++r) {
    State s = 0;
    std::vector<double> row(ntasks);
    if (!Get(data, &pos, &s)) return path + " is truncated";
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (!Get(data, &pos, &row[i])) return path + " is truncated";
      // The checksum is right, so the planner that saved it overflowed
      // (e.g. an older one fed an absurd delay): learning from it would
      // spread the inf or NaN to every state.
      if (!std::isfinite(row[i])) {
        std::ostringstream why;
        why << path << " has a non-finite Q-value (" << row[i] << " in state 0x" << std::hex << s << std::dec
            << " for task '" << graph_.tasks[i].name << "')";
        return why.str();
      }
    }
    table.q[s] = std::move(row);
  }
  if (pos != data.size()) return path + " has trailing bytes";
  *out = std::move(table);
  return std::nullopt;
}

bool TaskPlanner::Load(const std::string& path, std::string* note) {
  // Temporaries of saves killed before their rename (kill -9, power loss)
  // are never read; without this they pile up beside the table.
  const std::size_t stale =
      core::RemoveStaleTempFiles(path).size() + core::RemoveStaleTempFiles(path + ".bak").size();
  const bool loaded = LoadTable(path, note);
  if (note && stale > 0) *note += "; removed " + std::to_string(stale) + " stale temporary file(s)";
  return loaded;
}

bool TaskPlanner::LoadTable(const std::string& path, std::string* note) {
  const bool main_exists = std::ifstream(path).good(), backup_exists = std::ifstream(path + ".bak").good();
  if (!main_exists && !backup_exists) {
    if (note) *note = path + " does not exist: starting with an empty Q-table";
    return false;
  }
  const auto main_error = main_exists ? TryLoad(path) : std::optional<std::string>(path + " is missing");
  if (!main_error) {
    if (note) {
      *note = "loaded " + path + " (" + std::to_string(q_.size()) + " states, " + std::to_string(episodes_learned_) +
              " episodes learned)";
    }
    return true;
  }
  const auto backup_error = backup_exists ? TryLoad(path + ".bak") : std::optional<std::string>("no backup");
  if (!backup_error) {
    if (note) *note = *main_error + "; refused it and loaded the previous good table " + path + ".bak";
    return true;
  }
  throw std::runtime_error("cannot load the Q-table: " + *main_error + "; backup: " + *backup_error);
}

}  // namespace iplan::supervisor
