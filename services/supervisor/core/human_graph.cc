#include "services/supervisor/core/human_graph.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "iplan/core/config.h"
#include "iplan/core/params.h"

namespace iplan::supervisor {
namespace {

constexpr double kSumTolerance = 1e-6;

// "" when `p` is a distribution over known actions of `graph`, else why not.
std::string CheckDistribution(const std::map<std::string, double>& p, const HumanGraph& graph,
                              const std::vector<std::string>& human_actions) {
  if (p.empty()) return "is empty";
  double sum = 0;
  for (const auto& [name, prob] : p) {
    if (std::find(human_actions.begin(), human_actions.end(), name) == human_actions.end()) {
      return "names unknown human action '" + name + "'";
    }
    if (graph.Find(name) < 0) return "names '" + name + "', which has no entry in human_graph.actions";
    if (!(prob >= 0 && prob <= 1)) return "gives '" + name + "' a probability outside [0, 1]";
    sum += prob;
  }
  if (std::abs(sum - 1.0) > kSumTolerance) return "has probabilities summing to " + core::ParamText(sum) + ", not 1";
  return "";
}

// Picks a key of `p` by a uniform number u in [0, 1) (the map's order).
const std::string& Pick(const std::map<std::string, double>& p, double u) {
  double acc = 0;
  for (const auto& [name, prob] : p) {
    acc += prob;
    if (u < acc) return name;
  }
  return p.rbegin()->first;  // u within rounding of 1
}

// Survival of a duration uniform on [least, most] at age `tau` (s).
double Survival(const HumanActionStep& s, double tau) {
  const double a = s.duration[0], b = s.duration[1];
  if (tau < a) return 1.0;
  if (tau >= b) return 0.0;
  return (b - tau) / (b - a);
}

// Adds `p` of an action's mass to its age bins (bin b: age b dt): at the
// age `elapsed`, or, met part way through and at least that old, spread
// over the ages from there in proportion to the survival (the age of an
// action found in progress has that density; one already past its most
// ends at once).
void AddAged(const HumanActionStep& s, const ActionOutlook& outlook, double dt, double p, std::vector<double>* bins) {
  const std::size_t age = std::min(bins->size() - 1, static_cast<std::size_t>(std::max(0.0, outlook.elapsed) / dt));
  double total = 0;
  if (outlook.elapsed_at_least) {
    for (std::size_t b = age; b < bins->size(); ++b) total += Survival(s, b * dt);
  }
  if (!(total > 0)) {
    (*bins)[age] += p;
    return;
  }
  for (std::size_t b = age; b < bins->size(); ++b) (*bins)[b] += p * Survival(s, b * dt) / total;
}

}  // namespace

int HumanGraph::Find(const std::string& action) const {
  for (std::size_t i = 0; i < actions.size(); ++i) {
    if (actions[i].first == action) return static_cast<int>(i);
  }
  return -1;
}

std::string HumanGraph::Validate(const std::vector<std::string>& human_actions) const {
  if (empty()) return start.empty() ? "" : "human_graph.start is given but human_graph.actions is empty";
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const auto& [name, step] = actions[i];
    for (std::size_t j = 0; j < i; ++j) {
      if (actions[j].first == name) return "human_graph.actions: '" + name + "' is given twice";
    }
    if (std::find(human_actions.begin(), human_actions.end(), name) == human_actions.end()) {
      return "human_graph.actions: unknown human action '" + name + "'";
    }
    const double a = step.duration[0], b = step.duration[1];
    if (!(std::isfinite(a) && std::isfinite(b) && a > 0 && a <= b)) {
      return "human_graph.actions." + name + ".duration must be [least, most] with 0 < least <= most, got [" +
             core::ParamText(a) + ", " + core::ParamText(b) + "]";
    }
    if (const std::string why = CheckDistribution(step.next, *this, human_actions); !why.empty()) {
      return "human_graph.actions." + name + ".next " + why;
    }
  }
  if (const std::string why = CheckDistribution(start, *this, human_actions); !why.empty()) {
    return "human_graph.start " + why;
  }
  return "";
}

std::vector<HumanActionSpan> DrawHumanActions(const HumanGraph& graph, double until,
                                              const std::function<double()>& uniform01) {
  if (graph.empty()) throw std::invalid_argument("DrawHumanActions: the human graph is empty");
  if (!(until > 0)) throw std::invalid_argument("DrawHumanActions: until must be > 0");
  auto duration = [&](const std::string& action) {
    const auto& d = graph.actions[static_cast<std::size_t>(graph.Find(action))].second.duration;
    return d[0] + (d[1] - d[0]) * uniform01();
  };
  std::vector<HumanActionSpan> spans;
  HumanActionSpan first;
  first.action = Pick(graph.start, uniform01());
  first.duration = duration(first.action);
  first.start = -uniform01() * first.duration;
  spans.push_back(first);
  while (spans.back().end() < until) {
    const HumanActionStep& step = graph.actions[static_cast<std::size_t>(graph.Find(spans.back().action))].second;
    HumanActionSpan s;
    s.action = Pick(step.next, uniform01());
    s.start = spans.back().end();
    s.duration = duration(s.action);
    spans.push_back(s);
  }
  return spans;
}

ActionForecast ForecastActions(const HumanGraph& graph, const ActionOutlook& outlook, double dt, int steps) {
  if (!(dt > 0) || steps < 0) throw std::invalid_argument("ForecastActions: dt must be > 0 and steps >= 0");
  ActionForecast f;
  f.dt = dt;
  for (const auto& [name, step] : graph.actions) f.actions.push_back(name);
  const std::size_t n = graph.actions.size();
  for (const auto& [name, p] : outlook.belief) {
    if (graph.Find(name) < 0) f.actions.push_back(name);
  }
  const std::size_t m = f.actions.size();
  // Mass per graph action and age (bin k: age k dt); the ages reach past
  // the most, where every action has ended.
  std::vector<std::vector<double>> mass(n), next_mass(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t bins = static_cast<std::size_t>(std::ceil(graph.actions[i].second.duration[1] / dt)) + 2;
    mass[i].assign(bins, 0.0);
    next_mass[i].assign(bins, 0.0);
  }
  std::vector<double> lasting(m, 0.0);  // actions the graph does not know
  std::vector<double> pinned(n, 0.0);   // an oracle's current action, ending at `remaining`
  for (const auto& [name, p] : outlook.belief) {
    const int i = graph.Find(name);
    if (i < 0) {
      lasting[static_cast<std::size_t>(std::find(f.actions.begin(), f.actions.end(), name) - f.actions.begin())] += p;
    } else if (outlook.remaining >= 0) {
      pinned[static_cast<std::size_t>(i)] += p;
    } else {
      AddAged(graph.actions[static_cast<std::size_t>(i)].second, outlook, dt, p, &mass[static_cast<std::size_t>(i)]);
    }
  }
  // Where the mass of action i goes when it ends (the oracle's next for the
  // pinned action's first change).
  auto enter = [&](std::size_t i, double amount, bool first_change) {
    if (amount <= 0) return;
    const int known = first_change && !outlook.next.empty() ? graph.Find(outlook.next) : -1;
    if (known >= 0) {
      next_mass[static_cast<std::size_t>(known)][0] += amount;
      return;
    }
    for (const auto& [name, prob] : graph.actions[i].second.next) {
      next_mass[static_cast<std::size_t>(graph.Find(name))][0] += amount * prob;
    }
  };
  f.p.assign(static_cast<std::size_t>(steps), std::vector<double>(m, 0.0));
  for (int k = 0; k < steps; ++k) {
    std::vector<double>& out = f.p[static_cast<std::size_t>(k)];
    for (std::size_t i = 0; i < n; ++i) {
      out[i] = pinned[i];
      for (double v : mass[i]) out[i] += v;
    }
    for (std::size_t j = n; j < m; ++j) out[j] = lasting[j];
    // To the next step: the pinned action ends when its time is up; every
    // other action ends with its hazard over [k dt, (k + 1) dt).
    const bool pinned_ends = outlook.remaining >= 0 && outlook.remaining < (k + 1) * dt;
    for (std::size_t i = 0; i < n; ++i) {
      std::fill(next_mass[i].begin(), next_mass[i].end(), 0.0);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (pinned_ends) {
        enter(i, pinned[i], true);
        pinned[i] = 0;
      }
      const HumanActionStep& s = graph.actions[i].second;
      for (std::size_t b = 0; b < mass[i].size(); ++b) {
        const double v = mass[i][b];
        if (v <= 0) continue;
        const double alive = Survival(s, b * dt);
        const double ends = alive > 0 ? 1.0 - Survival(s, (b + 1) * dt) / alive : 1.0;
        enter(i, v * ends, false);
        if (b + 1 < mass[i].size()) next_mass[i][b + 1] += v * (1.0 - ends);
      }
    }
    std::swap(mass, next_mass);
  }
  return f;
}

std::string ActionTrackerParams::Validate() const {
  const core::Check<double> seconds = core::InRange(0.0, 10.0);
  if (const std::string why = seconds(action_switch_confirm); !why.empty()) return "action_switch_confirm " + why + " s";
  if (const std::string why = seconds(action_recognition_delay); !why.empty())
    return "action_recognition_delay " + why + " s";
  return "";
}

ActionTracker::ActionTracker(const ActionTrackerParams& params) : params_(params) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("ActionTracker: " + why);
}

void ActionTracker::Update(double stamp, const std::map<std::string, double>& belief) {
  if (belief.empty()) {
    action_.clear();
    candidate_.clear();
    start_seen_ = false;
    return;
  }
  const auto best = std::max_element(belief.begin(), belief.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  if (action_.empty()) {  // the first belief: its action began before it
    action_ = best->first;
    since_ = stamp;
    start_seen_ = false;
    candidate_.clear();
    return;
  }
  if (best->first == action_) {
    candidate_.clear();
    return;
  }
  if (best->first != candidate_) {
    candidate_ = best->first;
    candidate_since_ = stamp;
  }
  if (stamp - candidate_since_ >= params_.action_switch_confirm) {
    action_ = candidate_;
    since_ = candidate_since_;
    start_seen_ = true;
    candidate_.clear();
  }
}

double ActionTracker::Elapsed(double now) const {
  if (action_.empty()) return 0.0;
  return std::max(0.0, now - since_) + (start_seen_ ? params_.action_recognition_delay : 0.0);
}

ActionOutlook ActionTracker::Outlook(const std::map<std::string, double>& belief, double now) const {
  ActionOutlook o;
  o.belief = belief;
  o.elapsed = Elapsed(now);
  o.elapsed_at_least = !action_.empty() && !start_seen_;
  return o;
}

}  // namespace iplan::supervisor
