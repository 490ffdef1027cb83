#include "services/cloud/core/point_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace iplan::cloud_service {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;

bool Positive(double v) { return v > 0 && std::isfinite(v); }

}  // namespace

std::string MotionParams::Validate() const {
  if (!Positive(part_radius)) return "part_radius must be > 0 m";
  if (min_points < 1) return "min_points must be >= 1, got " + std::to_string(min_points);
  if (!Positive(measurement_sigma)) return "measurement_sigma must be > 0 m";
  if (!Positive(acceleration_density)) return "acceleration_density must be > 0 m^2/s^3";
  if (!Positive(initial_speed_sigma)) return "initial_speed_sigma must be > 0 m/s";
  if (!Positive(tracked_speed_sigma)) return "tracked_speed_sigma must be > 0 m/s";
  if (!(neighbour_speed_sigma >= 0 && std::isfinite(neighbour_speed_sigma))) return "neighbour_speed_sigma must be >= 0 m/s";
  if (!(visibility_sigma >= 0 && std::isfinite(visibility_sigma))) return "visibility_sigma must be >= 0 m";
  if (!Positive(gate)) return "gate must be > 0";
  if (lost_frames < 0) return "lost_frames must be >= 0, got " + std::to_string(lost_frames);
  if (!(merge_distance >= 0 && std::isfinite(merge_distance))) return "merge_distance must be >= 0 m";
  if (!Positive(max_gap)) return "max_gap must be > 0 s";
  return "";
}

MotionTracker::MotionTracker(const MotionParams& params) : params_(params) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument(why);
}

bool MotionTracker::Tracked(const MotionPart& part) const {
  if (part.measured < 2) return false;
  const double max_variance = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(part.velocity_covariance(),
                                                                             Eigen::EigenvaluesOnly)
                                  .eigenvalues()
                                  .maxCoeff();
  const double limit = params_.tracked_speed_sigma * params_.tracked_speed_sigma +
                       (part.from_neighbour ? params_.neighbour_speed_sigma * params_.neighbour_speed_sigma : 0.0);
  return max_variance <= limit;
}

std::optional<PartVelocity> MotionTracker::VelocityOf(std::size_t k) const {
  const MotionPart& part = parts_.at(k);
  if (Tracked(part)) return PartVelocity{part.velocity(), part.velocity_covariance()};
  const MotionPart* neighbour = NearestTracked(part.centre());
  if (!neighbour) return std::nullopt;
  return NextTo(*neighbour);
}

PartVelocity MotionTracker::NextTo(const MotionPart& neighbour) const {
  const double s2 = params_.neighbour_speed_sigma * params_.neighbour_speed_sigma;
  return PartVelocity{neighbour.velocity(), neighbour.velocity_covariance() + s2 * Eigen::Matrix3d::Identity()};
}

const MotionPart* MotionTracker::NearestTracked(const Eigen::Vector3d& centre) const {
  const MotionPart* neighbour = nullptr;
  double nearest = 4 * params_.part_radius * params_.part_radius;  // two part radii, squared
  for (const MotionPart& other : parts_) {
    const double d = (other.centre() - centre).squaredNorm();
    if (d <= nearest && Tracked(other)) nearest = d, neighbour = &other;
  }
  return neighbour;
}

// Constant velocity, continuous white-noise acceleration per axis (spectral
// density q = acceleration_density): x' = F x, P' = F P F^T + Q with
//   Q = q [dt^3/3  dt^2/2; dt^2/2  dt]
// per axis, so the velocity variance grows linearly with the time since the
// last frame: a gap of three frames costs what three frames do (the
// piecewise-constant model grew it with dt^2, and a dropped frame or two on
// a loaded host made every part untrusted).
void MotionTracker::Predict(double dt) {
  Matrix6d F = Matrix6d::Identity();
  F.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
  const double q = params_.acceleration_density;
  Matrix6d Q = Matrix6d::Zero();
  Q.topLeftCorner<3, 3>() = q * std::pow(dt, 3) / 3 * Eigen::Matrix3d::Identity();
  Q.topRightCorner<3, 3>() = q * dt * dt / 2 * Eigen::Matrix3d::Identity();
  Q.bottomLeftCorner<3, 3>() = Q.topRightCorner<3, 3>();
  Q.bottomRightCorner<3, 3>() = q * dt * Eigen::Matrix3d::Identity();
  for (MotionPart& p : parts_) {
    p.x = F * p.x;
    p.P = F * p.P * F.transpose() + Q;
  }
}

bool MotionTracker::BallCentroid(const std::vector<Eigen::Vector3d>& p_W, const Eigen::Vector3d& centre,
                                 Eigen::Vector3d* m, int* count) const {
  const double r2 = params_.part_radius * params_.part_radius;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const Eigen::Vector3d& p : p_W) {
    if ((p - centre).squaredNorm() <= r2) {
      sum += p;
      ++n;
    }
  }
  if (n < params_.min_points) return false;
  *m = sum / n;
  *count = n;
  return true;
}

// The measurement (file comment, step 2), then the Kalman update with it,
// down-weighted when its normalised innovation square d2 exceeds the gate
// (S scaled by d2 / gate); Joseph form, so the covariance stays symmetric
// positive definite with the scaled gain.
void MotionTracker::Measure(MotionPart* part, const std::vector<Eigen::Vector3d>& p_W) const {
  constexpr int kShifts = 3;           // ball re-centrings
  constexpr double kConverged = 1e-3;  // m
  Eigen::Vector3d x = part->centre(), m;
  int n = 0;
  if (!BallCentroid(p_W, x, &m, &n)) {
    ++part->unseen;
    return;
  }
  // The visible share changed: judged where the part was predicted, before
  // the ball is re-centred (which moves it towards the points left).
  const double change = std::abs(n - part->ball_points) / static_cast<double>(std::max(n, part->ball_points));
  for (int k = 0; k < kShifts; ++k) {
    const Eigen::Vector3d next = m - part->offset;
    Eigen::Vector3d m_next;
    int n_next = 0;
    if ((next - x).norm() < kConverged || !BallCentroid(p_W, next, &m_next, &n_next)) break;
    x = next;
    m = m_next;
  }
  const double sigma = params_.measurement_sigma + params_.visibility_sigma * change;
  Matrix36d H = Matrix36d::Zero();
  H.leftCols<3>().setIdentity();
  const Eigen::Matrix3d R = sigma * sigma * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d y = m - part->offset - part->centre();
  Eigen::Matrix3d S = H * part->P * H.transpose() + R;
  const double d2 = y.dot(S.ldlt().solve(y));
  if (d2 > params_.gate) S *= d2 / params_.gate;
  const Eigen::Matrix3d R_used = S - H * part->P * H.transpose();
  const Eigen::Matrix<double, 6, 3> K = part->P * H.transpose() * S.inverse();
  const Matrix6d I_KH = Matrix6d::Identity() - K * H;
  part->x += K * y;
  part->P = I_KH * part->P * I_KH.transpose() + K * R_used * K.transpose();
  part->P = 0.5 * (part->P + part->P.transpose());
  // The offset of this frame's ball at the new position: the next frame's
  // centroid is compared with this frame's content.
  Eigen::Vector3d m_post;
  int n_post = 0;
  if (BallCentroid(p_W, part->centre(), &m_post, &n_post)) {
    part->offset = m_post - part->centre();
    part->ball_points = n_post;
  }
  ++part->measured;
  part->unseen = 0;
}

// Points no part took seed new parts: the first one left, the points left
// within part_radius of it, then those within part_radius of their centroid.
void MotionTracker::Seed(const std::vector<Eigen::Vector3d>& p_W, std::vector<int>* part_of) {
  std::vector<int>& of = *part_of;
  const double r2 = params_.part_radius * params_.part_radius;
  for (std::size_t s = 0; s < p_W.size(); ++s) {
    if (of[s] >= 0) continue;
    Eigen::Vector3d centre = p_W[s];
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int n = 0;
      for (std::size_t i = s; i < p_W.size(); ++i) {
        if (of[i] < 0 && (p_W[i] - centre).squaredNorm() <= r2) {
          sum += p_W[i];
          ++n;
        }
      }
      if (n > 0) centre = sum / n;
    }
    MotionPart part;
    part.id = next_id_++;
    part.x.head<3>() = centre;
    Eigen::Vector3d m;
    if (BallCentroid(p_W, centre, &m, &part.ball_points)) part.offset = m - centre;  // all points, as Measure sees them
    part.P.setZero();
    part.P.topLeftCorner<3, 3>() =
        params_.measurement_sigma * params_.measurement_sigma * Eigen::Matrix3d::Identity();
    part.P.bottomRightCorner<3, 3>() =
        params_.initial_speed_sigma * params_.initial_speed_sigma * Eigen::Matrix3d::Identity();
    part.measured = 1;
    // Next to a tracked part (within two part radii: the same body, its
    // visible region grown), the new part starts from that part's velocity,
    // its covariance grown by neighbour_speed_sigma per axis (what a part of
    // a body may move relative to the next), and counts as tracked when that
    // is within tracked_speed_sigma.
    if (const MotionPart* neighbour = NearestTracked(centre)) {
      const PartVelocity v = NextTo(*neighbour);
      part.x.tail<3>() = v.velocity;
      part.P.bottomRightCorner<3, 3>() = v.covariance;
      part.measured = 2;
      part.from_neighbour = true;
    }
    const int index = static_cast<int>(parts_.size());
    for (std::size_t i = s; i < p_W.size(); ++i) {
      if (of[i] < 0 && (p_W[i] - centre).squaredNorm() <= r2) {
        of[i] = index;
        ++part.points;
      }
    }
    if (of[s] < 0) {  // the seed itself is farther than part_radius from the centroid
      of[s] = index;
      ++part.points;
    }
    parts_.push_back(part);
  }
}

// Drops lost parts and the younger of two close ones; points of a dropped
// part join the part that replaced it (the nearer survivor), indices remapped.
void MotionTracker::Prune(std::vector<int>* part_of) {
  const std::size_t n = parts_.size();
  std::vector<int> keep_as(n, -1);
  std::vector<char> drop(n, 0);
  for (std::size_t k = 0; k < n; ++k) drop[k] = parts_[k].unseen > params_.lost_frames;
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = a + 1; b < n && !drop[a]; ++b) {
      if (drop[b] || (parts_[a].centre() - parts_[b].centre()).norm() >= params_.merge_distance) continue;
      const bool a_older = parts_[a].measured > parts_[b].measured ||
                           (parts_[a].measured == parts_[b].measured && parts_[a].id < parts_[b].id);
      drop[a_older ? b : a] = 1;
    }
  }
  std::vector<MotionPart> kept;
  for (std::size_t k = 0; k < n; ++k) {
    if (drop[k]) continue;
    keep_as[k] = static_cast<int>(kept.size());
    kept.push_back(parts_[k]);
  }
  // A dropped part's points go to the nearest kept part (every point keeps one).
  for (std::size_t k = 0; k < n; ++k) {
    if (!drop[k] || kept.empty()) continue;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < kept.size(); ++j) {
      const double d = (kept[j].centre() - parts_[k].centre()).squaredNorm();
      if (d < best) {
        best = d;
        keep_as[k] = static_cast<int>(j);
      }
    }
  }
  for (int& k : *part_of) {
    if (k >= 0) k = keep_as[static_cast<std::size_t>(k)];
  }
  parts_ = std::move(kept);
}

std::vector<int> MotionTracker::Update(const std::vector<Eigen::Vector3d>& p_W, int64_t stamp_ns) {
  const double dt = (stamp_ns - last_stamp_ns_) * 1e-9;
  if (last_stamp_ns_ == 0 || !(dt >= 0) || dt > params_.max_gap) parts_.clear();
  else if (dt > 0) Predict(dt);
  last_stamp_ns_ = stamp_ns;
  for (MotionPart& p : parts_) Measure(&p, p_W);
  // Each point to the nearest part within part_radius.
  std::vector<int> part_of(p_W.size(), -1);
  const double r2 = params_.part_radius * params_.part_radius;
  for (MotionPart& p : parts_) p.points = 0;
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    double best = r2;
    for (std::size_t k = 0; k < parts_.size(); ++k) {
      const double d = (p_W[i] - parts_[k].centre()).squaredNorm();
      if (d <= best) {
        best = d;
        part_of[i] = static_cast<int>(k);
      }
    }
    if (part_of[i] >= 0) ++parts_[static_cast<std::size_t>(part_of[i])].points;
  }
  Seed(p_W, &part_of);
  Prune(&part_of);
  return part_of;
}

}  // namespace iplan::cloud_service
