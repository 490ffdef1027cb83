#include "iplan/collision/joint_mixture.h"

namespace iplan::collision {

void JointMixture::Resize(int num_actions, int steps, int num_joints) {
  const std::size_t A = static_cast<std::size_t>(num_actions);
  const std::size_t n = static_cast<std::size_t>(steps) * static_cast<std::size_t>(num_joints);
  num_steps = steps;
  actions.resize(A);
  probabilities.resize(A);
  means.resize(A);
  covariances.resize(A);
  for (std::size_t a = 0; a < A; ++a) {
    means[a].resize(n, Eigen::Vector3d::Zero());
    covariances[a].resize(n, Eigen::Matrix3d::Zero());
  }
}

JointGaussian JointMixture::Combined(int step, int joint) const {
  JointGaussian g;
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (int a = 0; a < num_actions(); ++a) {
    const Eigen::Vector3d& mu = Mean(a, step, joint);
    const double p = probabilities[static_cast<std::size_t>(a)];
    g.mean += p * mu;
    second += p * (Covariance(a, step, joint) + mu * mu.transpose());
  }
  g.covariance = second - g.mean * g.mean.transpose();
  return g;
}

int JointMixture::MostLikely() const {
  int best = 0;
  for (int a = 1; a < num_actions(); ++a) {
    if (probabilities[static_cast<std::size_t>(a)] > probabilities[static_cast<std::size_t>(best)]) best = a;
  }
  return best;
}

std::optional<std::string> BuildSpherePrediction(const HumanBodyModel& body, const JointMixture& in,
                                                 HumanPrediction* out) {
  const int A = static_cast<int>(in.actions.size());
  if (A == 0 || in.num_steps <= 0 || !(in.time_step > 0)) return std::string("empty prediction");
  if (static_cast<int>(in.probabilities.size()) != A || static_cast<int>(in.means.size()) != A ||
      static_cast<int>(in.covariances.size()) != A) {
    return std::string("prediction sizes are inconsistent");
  }
  const auto& wanted = body.params().joints;
  std::vector<std::size_t> idx(wanted.size());
  for (std::size_t w = 0; w < wanted.size(); ++w) {
    std::size_t i = 0;
    while (i < in.joint_names.size() && in.joint_names[i] != wanted[w]) ++i;
    if (i == in.joint_names.size()) return "prediction: missing joint '" + wanted[w] + "'";
    idx[w] = i;
  }
  const std::size_t J = in.joint_names.size();
  *out = body.MakePrediction(A, in.num_steps);
  Eigen::Matrix3Xd means(3, body.num_joints());
  std::vector<Eigen::Matrix3d> covs(static_cast<std::size_t>(body.num_joints()));
  for (int a = 0; a < A; ++a) {
    if (in.means[a].size() != J * static_cast<std::size_t>(in.num_steps) || in.covariances[a].size() != in.means[a].size()) {
      return "prediction action " + std::to_string(a) + " has the wrong number of Gaussians";
    }
    out->set_action_probability(a, in.probabilities[a]);
    for (int k = 0; k < in.num_steps; ++k) {
      for (int j = 0; j < body.num_joints(); ++j) {
        const std::size_t src = static_cast<std::size_t>(k) * J + idx[static_cast<std::size_t>(j)];
        means.col(j) = in.means[a][src];
        covs[static_cast<std::size_t>(j)] = in.covariances[a][src];
      }
      if (!body.FillPrediction(means, covs, a, k, out)) {
        return "prediction action " + std::to_string(a) + " step " + std::to_string(k) +
               ": a sphere covariance is not positive definite";
      }
    }
  }
  out->UpdateSummaries();
  return std::nullopt;
}

}  // namespace iplan::collision
