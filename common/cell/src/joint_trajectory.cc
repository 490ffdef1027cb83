#include "iplan/cell/joint_trajectory.h"

#include <algorithm>
#include <cmath>

namespace iplan::cell {

std::optional<std::string> MapJointNames(const std::vector<std::string>& names,
                                         const std::vector<std::string>& wanted,
                                         std::vector<int>* index) {
  index->assign(wanted.size(), -1);
  for (std::size_t w = 0; w < wanted.size(); ++w) {
    const auto it = std::find(names.begin(), names.end(), wanted[w]);
    if (it == names.end()) return "missing joint '" + wanted[w] + "'";
    (*index)[w] = static_cast<int>(it - names.begin());
  }
  return std::nullopt;
}

Eigen::VectorXd JointTrajectory::PositionAt(int64_t t_ns) const {
  const double t = static_cast<double>(t_ns - start_ns) * 1e-9;
  if (t <= times.front()) return positions.front();
  if (t >= times.back()) return positions.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double u = (t - times[i - 1]) / (times[i] - times[i - 1]);
  return (1 - u) * positions[i - 1] + u * positions[i];
}

JointTrajectory JointTrajectory::Uniform(int64_t start_ns, double dt, const Eigen::MatrixXd& Q) {
  JointTrajectory t;
  t.start_ns = start_ns;
  for (Eigen::Index i = 0; i < Q.cols(); ++i) {
    t.times.push_back(static_cast<double>(i) * dt);
    t.positions.emplace_back(Q.col(i));
  }
  return t;
}

std::optional<std::string> JointTrajectory::FromPoints(int64_t start_ns, const std::vector<std::string>& names,
                                                       const std::vector<double>& times,
                                                       const std::vector<std::vector<double>>& points,
                                                       const std::vector<std::string>& model_names,
                                                       JointTrajectory* out) {
  if (times.empty()) return std::string("no points");
  if (times.size() != points.size()) return std::string("times and points differ in size");
  std::vector<int> idx;
  if (auto e = MapJointNames(names, model_names, &idx)) return e;
  JointTrajectory t;
  t.start_ns = start_ns;
  t.times = times;
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (points[p].size() != names.size()) return "point " + std::to_string(p) + " has the wrong size";
    if (!std::isfinite(times[p])) return "time of point " + std::to_string(p) + " is not finite";
    if (p > 0 && !(times[p] > times[p - 1])) return std::string("times do not increase");
    Eigen::VectorXd q(static_cast<Eigen::Index>(model_names.size()));
    for (std::size_t i = 0; i < model_names.size(); ++i) {
      q[static_cast<Eigen::Index>(i)] = points[p][static_cast<std::size_t>(idx[i])];
      if (!std::isfinite(q[static_cast<Eigen::Index>(i)]))
        return "point " + std::to_string(p) + " has a non-finite position of " + model_names[i];
    }
    t.positions.push_back(std::move(q));
  }
  *out = std::move(t);
  return std::nullopt;
}

void FiniteDifferenceVelocities(const Eigen::MatrixXd& Q, double dt, Eigen::MatrixXd* V) {
  const Eigen::Index n = Q.cols() - 1;
  V->resize(Q.rows(), n);
  for (Eigen::Index i = 0; i < n; ++i) V->col(i) = (Q.col(i + 1) - Q.col(i)) / dt;
}

void FiniteDifferenceAccelerations(const Eigen::MatrixXd& Q, const Eigen::VectorXd& qdot0, double dt,
                                   Eigen::MatrixXd* A) {
  const Eigen::Index n = Q.cols() - 1;
  A->resize(Q.rows(), n + 1);
  for (Eigen::Index i = 0; i <= n; ++i) {
    const Eigen::VectorXd prev = i == 0 ? Eigen::VectorXd(Q.col(0) - qdot0 * dt) : Eigen::VectorXd(Q.col(i - 1));
    const Eigen::VectorXd next = i == n ? Eigen::VectorXd(Q.col(n)) : Eigen::VectorXd(Q.col(i + 1));
    A->col(i) = (next - 2.0 * Q.col(i) + prev) / (dt * dt);
  }
}

}  // namespace iplan::cell
