// The demo cell's intent model: trained from the synthetic person's recorded
// demonstrations on first use and cached next to the intent service's
// configuration (with a key file, so that a changed person retrains it).
#pragma once

#include <cstdint>
#include <string>

#include "services/perception/core/synthetic_person.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cli {

/// The demonstrations the cell's intent model is trained on: the synthetic
/// person `person` doing every action (several simulated people, two
/// recordings each, 30 Hz, with its sensor noise). Deterministic.
intent::SkeletonDataset RecordCellDemonstrations(const perception::SyntheticPersonParams& person);

/// The person of `perception_yaml` (perception.synthetic) as the cell sees
/// them, for evaluating the cell's model: `people` simulated people (s01,
/// s02, ...), two episodes each of the whole script (perception::RecordEpisodes:
/// 2 s idle before it, 2 s after, 30 Hz), drawn with generator seed `seed` (the
/// training demonstrations use the person's own seed), with each frame's
/// action and reaching flags. Throws std::runtime_error for an unreadable or
/// invalid file, std::invalid_argument for a person without a script.
intent::SkeletonDataset RecordCellEpisodes(const std::string& perception_yaml, std::uint64_t seed, int people);

/// The synthetic person's seed in `perception_yaml` (the training seed).
std::uint64_t CellPersonSeed(const std::string& perception_yaml);

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
