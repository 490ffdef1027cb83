// Predicting the separation monitor (PlannerParams::predict_ssm): the
// monitor's ISO/TS 15066 pair rule (safety::SsmPairRule, the same function the
// collision-risk monitor applies) evaluated along a plan against the
// predicted person.
//
// At free waypoint i (time t_i <= ssm_horizon after waypoint 0):
//  - robot sphere s at p_i, moving at v_r = (p_{i+1} - p_i) / dt (the plan's
//    own speed; at rest at the goal);
//  - human sphere l of each action c (p(c) >= kMinProbability) at the
//    action's mean mu at the waypoint's prediction step, moving at
//    (mu(step + 1) - mu(step)) / prediction dt (the last step's speed at
//    the end);
//    plus its speed allowance straight at the robot sphere
//    (HumanPrediction::speed_allowance: what the monitor adds for a depth
//    point not tracked, or for a tracked part's velocity uncertainty);
//  - margin m = d - S_p(v_h, v_r) of the pair rule; with
//    ssm_predicts_slowing, v_r at the monitor's min_speed_scale (the
//    monitor slows a robot down to that before it stops it). The pair violates when
//    m < ssm_margin and the robot sphere is not retreating (moving away at
//    kRetreatFactor x retreat_speed or faster: the monitor's retreat rule
//    with room for the interpolation between waypoints).
// The waypoint is unsafe when the actions with a violating pair there have
// a total probability >= ssm_stop_probability (per person): the monitor
// would more likely than not stop the plan (with the default 0.5). An
// unlikely action does not block a goal; if it comes true, the prediction
// says so within a few frames and the next plan yields.
// cost = w sum p(c) max(0, ssm_activation - m)^2 over the pairs (retreats
// cost nothing) at waypoints where the actions with a pair within the
// activation band have ssm_stop_probability or more; its gradient moves p_i
// away from mu (d grows) and lowers v_r (through p_i and p_{i+1}).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "iplan/safety/ssm.h"
#include "planner_model.h"

namespace iplan::planning::internal {
namespace {

// The planner asks for this times the monitor's retreat speed.
constexpr double kRetreatFactor = 2.0;
// Actions less likely than this are not judged (nor cost anything).
constexpr double kMinProbability = 0.05;

// dS_p / dv_r of safety::ProtectiveSeparationDistance at v_r (directed).
double ProtectiveSeparationSlope(const safety::SsmParams& s, double v_r) {
  double slope = s.reaction_time;
  if (!s.directed || v_r < s.stopping_speed) slope += s.directed ? s.stopping_distance / s.stopping_speed : 0.0;
  return slope;
}

// The probability of the actions in `bits` (a prediction's probabilities
// sum to at most 1; what is missing is no action the model knows).
double ActionMass(const collision::HumanPrediction& hp, std::uint64_t bits) {
  double mass = 0.0;
  for (int a = 0; a < hp.num_actions() && a < 64; ++a)
    if (bits >> a & 1) mass += hp.action_probability(a);
  return mass;
}

}  // namespace

int PlannerModel::SsmLastWaypoint(const Problem& at) const {
  if (!params.predict_ssm || at.people.empty()) return -1;
  return std::min(at.n, static_cast<int>(std::floor(params.ssm_horizon / at.dt + 1e-9)));
}

double PlannerModel::SsmRuleSpeedScale() const {
  return params.ssm_predicts_slowing && params.ssm.speed_reduction ? params.ssm.min_speed_scale : 1.0;
}

void PlannerModel::VisitSsmPairs(const Problem& at, const std::vector<collision::RobotData>& data, int from, int to,
                                 const SsmPairVisitor& visit) const {
  const safety::SsmParams& s = params.ssm;
  const double rule_scale = SsmRuleSpeedScale();
  const double reach = at.ssm_activation;
  const int S = static_cast<int>(radii.size());
  Eigen::Matrix3Xd v_robot(3, S);
  for (int i = from; i <= to; ++i) {
    const collision::RobotData& d = data[static_cast<std::size_t>(i)];
    if (i < at.n) {
      v_robot = (data[static_cast<std::size_t>(i + 1)].p_WS - d.p_WS) / at.dt;
    } else {
      v_robot.setZero();
    }
    const double v_r_max = v_robot.colwise().norm().maxCoeff();
    for (std::size_t p = 0; p < at.people.size(); ++p) {
      const Problem::Person& person = at.people[p];
      const collision::HumanPrediction& hp = *person.prediction;
      const int t = person.steps[static_cast<std::size_t>(i)];
      const int t_next = std::min(t + 1, hp.num_steps() - 1), t_prev = t_next == t ? std::max(0, t - 1) : t;
      const int H = hp.num_spheres();
      for (std::size_t g = 0; g < link_groups.size(); ++g) {
        Eigen::Vector3d c;
        const double cover = LinkBall(d, link_groups[g], &c);
        for (int l = 0; l < H; ++l) {
          const collision::HumanPrediction::Summary& sm = hp.summary(t, l);
          // Any pair of this group and sphere l: S_p is at most that of the
          // fastest robot sphere and the fastest action's mean speed.
          const double far = (c - sm.centre).norm() - sm.spread - cover - hp.radius(l);
          const double allowance = hp.speed_allowance(l);
          if (far >= reach + safety::ProtectiveSeparationDistance(s, allowance, v_r_max)) {
            double v_h_max = 0.0;
            if (t_next > t_prev) {
              for (int a = 0; a < hp.num_actions(); ++a)
                v_h_max = std::max(v_h_max, (hp.sphere(a, t_next, l).mean - hp.sphere(a, t_prev, l).mean).norm());
              v_h_max /= person.time_step * (t_next - t_prev);
            }
            if (far >= reach + safety::ProtectiveSeparationDistance(s, v_h_max + allowance, v_r_max)) continue;
          }
          for (int a = 0; a < hp.num_actions(); ++a) {
            const double pa = hp.action_probability(a);
            if (pa < kMinProbability) continue;
            const Eigen::Vector3d& mu = hp.sphere(a, t, l).mean;
            const Eigen::Vector3d v_h =
                t_next > t_prev ? Eigen::Vector3d((hp.sphere(a, t_next, l).mean - hp.sphere(a, t_prev, l).mean) /
                                                  (person.time_step * (t_next - t_prev)))
                                : Eigen::Vector3d::Zero();
            for (int sp : link_groups[g]) {
              const Eigen::Vector3d delta = d.p_WS.col(sp) - mu;
              // The monitor's allowance, straight at the robot sphere.
              const double len = delta.norm();
              const Eigen::Vector3d v_pair =
                  allowance > 0 && len > 1e-9 ? Eigen::Vector3d(v_h + allowance / len * delta) : v_h;
              const safety::SsmPair pair =
                  safety::SsmPairRule(s, delta, radii[sp] + hp.radius(l), v_pair, rule_scale * v_robot.col(sp));
              if (pair.margin >= reach) continue;
              const double away = delta.norm() > 1e-9 ? v_robot.col(sp).dot(delta.normalized()) : 0.0;
              const bool retreat = s.retreat_speed > 0 && away >= kRetreatFactor * s.retreat_speed;
              if (!visit(SsmVisit{i, static_cast<int>(p), a, sp, pa, retreat}, delta, pair)) return;
            }
          }
        }
      }
    }
  }
}

void PlannerModel::AddSsmCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const {
  const int last = std::min(SsmLastWaypoint(at), at.n - 1);
  if (last < at.k) return;
  const double w = params.weights.ssm, act = at.ssm_activation;
  const safety::SsmParams& s = params.ssm;
  const double rule_scale = SsmRuleSpeedScale();  // v_r of a pair is the plan's speed x this
  // The pairs within the activation band (not retreating), and per waypoint
  // and person the actions they belong to: only where those actions are
  // likely enough to stop the plan (ssm_stop_probability) do they cost, so
  // that an unlikely action shapes nothing, as it blocks nothing.
  const std::size_t P = at.people.size();
  std::vector<SsmNearPair>& near = ws->ssm_near;
  near.clear();
  ws->ssm_actions.assign(static_cast<std::size_t>(at.n + 1) * P, 0);
  VisitSsmPairs(at, ws->data, at.k, last, [&](const SsmVisit& v, const Eigen::Vector3d& delta, const safety::SsmPair& pair) {
    if (v.retreat || v.action >= 64) return true;
    near.push_back({v, delta, pair});
    ws->ssm_actions[static_cast<std::size_t>(v.waypoint) * P + static_cast<std::size_t>(v.person)] |= std::uint64_t{1}
                                                                                                      << v.action;
    return true;
  });
  for (const SsmNearPair& np : near) {
    const SsmVisit& v = np.at;
    const std::uint64_t actions = ws->ssm_actions[static_cast<std::size_t>(v.waypoint) * P + static_cast<std::size_t>(v.person)];
    const collision::HumanPrediction& hp = *at.people[static_cast<std::size_t>(v.person)].prediction;
    if (ActionMass(hp, actions) < params.ssm_stop_probability * (1.0 - 1e-9)) continue;
    const int i = v.waypoint, sp = v.sphere;
    const double e = act - np.pair.margin;
    ev->ssm += w * v.probability * e * e;
    if (!G) continue;
    const double len = np.delta.norm();
    if (len < 1e-9) continue;
    const Eigen::Vector3d u = np.delta / len;  // human -> robot
    // dm/dp_i = u (+ slope / dt u while approaching), dm/dp_{i+1} = -slope / dt u.
    const double k_v = np.pair.v_r > 0 ? rule_scale * ProtectiveSeparationSlope(s, np.pair.v_r) / at.dt : 0.0;
    const double scale = -2.0 * w * v.probability * e;
    const collision::RobotData& d = ws->data[static_cast<std::size_t>(i)];
    chains->AddPointGradient(d, links[sp], d.p_WS.col(sp), scale * (1.0 + k_v) * u, G->col(i));
    if (k_v > 0 && i + 1 < at.n) {
      const collision::RobotData& d1 = ws->data[static_cast<std::size_t>(i + 1)];
      chains->AddPointGradient(d1, links[sp], d1.p_WS.col(sp), -scale * k_v * u, G->col(i + 1));
    }
  }
}

SsmJudgement PlannerModel::JudgeSsm(const Problem& at, const Eigen::MatrixXd& Q, int from, int to,
                                    Workspace* ws) const {
  SsmJudgement j;
  const int last = std::min(to, SsmLastWaypoint(at));
  from = std::max(from, 1);
  if (last < from) return j;
  // FK into the thread's scratch (ws->data: Evaluate recomputes what it needs).
  std::vector<collision::RobotData>& data = ws->data;
  while (static_cast<int>(data.size()) < at.n + 1) data.emplace_back(robot);
  for (int i = from; i <= std::min(at.n, last + 1); ++i) collision::CalcForwardKinematics(robot, Q.col(i), &data[i]);
  // Per waypoint and person: the actions with a violating pair (bit a), and
  // the tightest such pair.
  const std::size_t P = at.people.size();
  std::vector<std::uint64_t>& stopped = ws->ssm_actions;
  stopped.assign(static_cast<std::size_t>(last + 1) * P, 0);
  std::vector<safety::SsmPair>& tightest = ws->ssm_tightest;
  tightest.resize(stopped.size());
  VisitSsmPairs(at, data, from, last, [&](const SsmVisit& v, const Eigen::Vector3d&, const safety::SsmPair& pair) {
    if (v.retreat) return true;
    if (v.probability >= kSeparationMinProbability) j.min_margin = std::min(j.min_margin, pair.margin);
    if (pair.margin < at.ssm_margin && v.action < 64) {
      const std::size_t e = static_cast<std::size_t>(v.waypoint) * P + static_cast<std::size_t>(v.person);
      if (stopped[e] == 0 || pair.margin < tightest[e].margin) tightest[e] = pair;
      stopped[e] |= std::uint64_t{1} << v.action;
    }
    return true;
  });
  for (int i = from; i <= last && j.ok(); ++i) {
    for (std::size_t p = 0; p < P; ++p) {
      const std::size_t e = static_cast<std::size_t>(i) * P + p;
      if (stopped[e] == 0) continue;
      const double mass = ActionMass(*at.people[p].prediction, stopped[e]);
      if (mass >= params.ssm_stop_probability * (1.0 - 1e-9)) {
        j.first_violation = i;
        j.violation = tightest[e];
        j.stop_probability = mass;
        break;
      }
    }
  }
  return j;
}

}  // namespace iplan::planning::internal
