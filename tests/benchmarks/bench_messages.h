// The messages the DDS benchmarks send: a skeleton (9 joints with
// covariance, about 1 KB) and a 10-action prediction (10 actions x 15 steps x
// 9 joints of Gaussians, about 130 KB). Units as in the IDL (m, m^2, s).
#pragma once

#include <string>

#include "iplan/msg/types.h"

namespace iplan::bench {

inline msg::HumanSkeleton MakeSkeleton() {
  msg::HumanSkeleton s;
  s.header.frame_id = "world";
  s.body_id = 1;
  s.confidence = 1;
  const char* names[] = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l", "shoulder_r", "elbow_r", "hand_r"};
  for (int j = 0; j < 9; ++j) {
    msg::HumanJoint h;
    h.name = names[j];
    h.position.x = 0.1 * j;
    h.covariance = {1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4};
    h.confidence = 1;
    s.joints.push_back(h);
  }
  return s;
}

inline msg::HumanPrediction MakePrediction() {
  msg::HumanPrediction p;
  p.header.frame_id = "world";
  p.body_id = 1;
  p.time_step = 1.0 / 15;
  p.num_steps = 15;
  p.joint_names = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l", "shoulder_r", "elbow_r", "hand_r"};
  for (int a = 0; a < 10; ++a) {
    msg::ActionPrediction ap;
    ap.action = "action_" + std::to_string(a);
    ap.probability = 0.1;
    ap.joints.resize(15 * 9);
    for (auto& g : ap.joints) {
      g.mean.x = 0.5;
      g.covariance = {1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3};
    }
    p.actions.push_back(ap);
  }
  return p;
}

}  // namespace iplan::bench
