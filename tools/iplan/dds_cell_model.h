// The demo cell's intent model: trained from the synthetic person's recorded
// demonstrations on first use and cached next to the intent service's
// configuration (with a key file, so that a changed person retrains it).
#pragma once

#include <string>

#include "perception/core/synthetic_person.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cli {

/// The demonstrations the cell's intent model is trained on: the synthetic
/// person `person` doing every action (several simulated people, two
/// recordings each, 30 Hz, with its sensor noise). Deterministic.
intent::SkeletonDataset RecordCellDemonstrations(const perception::SyntheticPersonParams& person);

struct CellModelResult {
  std::string path;     ///< model file to use
  bool trained = false; ///< trained now (false: the cache was valid)
  double seconds = 0;   ///< training time
  std::string summary;  ///< one line for the user
};

/// Ensures the intent model named by `intent_yaml` (intent.model) exists and
/// was trained for the person of `perception_yaml` (perception.synthetic) and
/// for intent.joints / intent.rate_hz. Trains and writes it atomically when
/// missing or stale; if its folder is not writable, writes it under
/// `fallback_dir` instead (the caller then points the service at `path`).
/// Throws std::runtime_error with the reason.
CellModelResult EnsureCellModel(const std::string& perception_yaml, const std::string& intent_yaml,
                                const std::string& fallback_dir, bool force);

}  // namespace iplan::cli
