// Reads the synthetic person's settings (perception.synthetic in
// perception.yaml). Shared by the perception service and `iplan demo`, which
// records the same person's demonstrations to train the intent models.
#pragma once

#include "core/synthetic_person.h"
#include "iplan/framework/config.h"

namespace iplan::perception {

/// How the synthetic person's script is started.
enum class ScriptStart {
  kLoop,      ///< at start-up, repeated for ever
  kEpisodes,  ///< with each task-planning episode (the first task command of an episode)
};

/// Reads `section` (perception.synthetic) into params; problems are recorded
/// in the configuration (reported by Finish()). Keys: torso, facing_yaw,
/// noise_stddev, variation, transition, rest_hand, seed, start, actions, script,
/// durations, more_people.
///
/// more_people: the further persons of the cell (bodies 2, 3, ...), a list
/// of mappings with the keys torso (m, world frame), facing_yaw (rad) and
/// seed, each defaulting to the first person's (seed: the first person's +
/// the person's index); everything else (actions, script, noise) is the
/// first person's. Default empty: one person. Into *others when not null
/// (the keys are checked either way).
SyntheticPersonParams ReadSyntheticPerson(framework::ConfigSection& section, ScriptStart* start,
                                          std::vector<SyntheticPersonParams>* others = nullptr);

}  // namespace iplan::perception
