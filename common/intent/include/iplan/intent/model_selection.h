// Choosing between model options by cross-validation without chasing noise:
// the one-standard-error rule (Breiman et al. 1984; Hastie, Tibshirani and
// Friedman, "The Elements of Statistical Learning", 7.10): of the options
// whose held-out error is within one standard error of the best one, take the
// simplest. Used for the forecaster's design (docs/intent.md, pipeline step
// 5): a gain smaller than the fold-to-fold scatter is not taken for a gain.
#pragma once

#include <Eigen/Core>

namespace iplan::intent {

/// `fold_error` (O options, F folds): the mean held-out error of each option
/// in each fold (any unit), the options ordered from the simplest (row 0) to
/// the most complex; a fold with a non-finite entry is left out. Returns the
/// first option o whose mean paired difference to the best option b (lowest
/// mean error), mean_f (e_of - e_bf), is at most one standard error of that
/// mean (sample standard deviation over the folds / sqrt(F)). With fewer than
/// two usable folds: the best option (0 with none). Thread-safe; allocates.
int SimplestWithinOneStandardError(const Eigen::MatrixXd& fold_error);

}  // namespace iplan::intent
