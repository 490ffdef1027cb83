#include "iplan/cell/ssm.h"

#include <algorithm>

namespace iplan::cell {

double StoppingDistance(const SsmParams& p, double v_r) {
  return p.directed ? p.stopping_distance * std::min(1.0, v_r / p.stopping_speed) : p.stopping_distance;
}

double ProtectiveSeparationDistance(const SsmParams& p, double v_h, double v_r) {
  const double s_h = v_h * (p.reaction_time + p.stopping_time);
  const double s_r = v_r * p.reaction_time;
  const double fixed = p.intrusion_distance + p.sensing_uncertainty + p.robot_uncertainty;
  return s_h + s_r + StoppingDistance(p, v_r) + fixed;
}

}  // namespace iplan::cell
