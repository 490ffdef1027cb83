// Dynamic time warping with a Sakoe-Chiba band, and the DTW kernel.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace iplan::intent {

/// DTW distance between two sequences of frames, rows = frames:
/// `a` (n, d), `b` (m, d), same d >= 1, n, m >= 1. The frame-to-frame cost is
/// the Euclidean distance; the distance is the minimum total cost over
/// monotone warping paths from (0, 0) to (n-1, m-1) with steps (1,0), (0,1),
/// (1,1), restricted to |i - j| <= w with w = max(band, |n - m|) (band < 0:
/// no restriction). Units: those of the frames.
/// Throws std::invalid_argument on empty input or mismatched d.
/// Thread-safe; allocates O(m).
double DtwDistance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, int band);

/// Same as DtwDistance() with frames as columns: `a` (d, n), `b` (d, m).
/// `workspace` is resized as needed (reuse it to avoid allocation). No input
/// checks beyond debug assertions: for hot loops.
double DtwDistanceColumns(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                          int band, std::vector<double>* workspace);

/// DTW kernel K = exp(-DTW^2 / (2 sigma^2)) for a DTW distance `dtw` and
/// width `sigma` > 0 (same units). Not positive definite in general.
double DtwKernel(double dtw, double sigma);

}  // namespace iplan::intent
