// Intent model files.
//
// Binary layout (little-endian):
//   "IPLANINT" (8 bytes) | format version (u32) | payload size (u64) |
//   payload | FNV-1a 64-bit checksum of the payload (u64).
// Doubles are stored as their raw IEEE-754 bits, so save -> load -> save is
// byte-identical and a loaded model predicts bit-identically.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "iplan/intent/intent_model.h"

namespace iplan::intent {

/// The format version this build writes.
/// 2: the classifier stores its belief-filter parameters.
/// 3: the forecast settings (kinematic baseline, residual weight, covariance
///    calibration and activity scaling) follow the forecasters at the end of
///    the payload.
/// 4: the configuration stores IntentModelConfig::history_samples (the
///    forecaster's history inputs; read as 0 from older files).
inline constexpr std::uint32_t kIntentModelFormatVersion = 4;
/// The oldest version this build still reads: a version-2 file is read with
/// the forecast settings that reproduce its predictions (ForecastSettings).
inline constexpr std::uint32_t kOldestReadableIntentModelFormatVersion = 2;

/// What the user of a model (a service, the CLI) is configured for. Empty /
/// unset fields are not checked.
struct ModelExpectation {
  std::vector<std::string> joints;  ///< Joint names, in order.
  std::optional<double> rate;       ///< Hz; compared with a 1e-9 relative tolerance.
};

/// Serialises `model` to bytes (the complete file contents).
std::string SerializeIntentModel(const IntentModel& model);

/// Parses file contents. Throws std::runtime_error with a clear message for a
/// wrong magic, a format version outside
/// [kOldestReadableIntentModelFormatVersion, kIntentModelFormatVersion], a checksum mismatch (corrupt or
/// truncated file), or an inconsistent payload. `source` names the file in
/// messages.
IntentModel DeserializeIntentModel(const std::string& bytes, const std::string& source);

/// Writes the model atomically: a temporary file in the same directory is
/// written, fsync'ed and renamed over `path` (the directory is fsync'ed too),
/// so readers see either the old or the new complete file.
/// Throws std::runtime_error naming the path and the system error.
void SaveIntentModel(const IntentModel& model, const std::string& path);

/// Reads a model file and, if `expected` is given, checks that the model's
/// joint set and rate match it. Throws std::runtime_error naming the file and
/// the mismatching values and the first mismatching joint (e.g. "model
/// joints [a,b] do not match the configured joints [a,c]: configured joint
/// 'c' is not a model joint").
IntentModel LoadIntentModel(const std::string& path,
                            const ModelExpectation& expected = ModelExpectation{});

}  // namespace iplan::intent
