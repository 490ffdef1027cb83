// Task places for the robot at hand: a task graph may give a goal or retreat
// as joint positions, as a tool pose in the cell frame (ToolPose), or both;
// ResolveTaskGoals turns every one into joint positions of the planner's
// robot with the planner's IK, so one cell description serves any arm and
// the rest of the cell (supervisor, trajopt, cell-check, eval) works in
// joints as before. No DDS types.
#pragma once

#include <string>
#include <vector>

#include "services/supervisor/core/task_planner.h"
#include "iplan/planning/planner.h"

namespace iplan::supervisor {

struct GoalOptions {
  /// How far joint positions given beside a pose may put the end effector
  /// from that pose and still be used (they are then the robot's own choice
  /// of solution, e.g. the Panda's hand-picked elbow).
  double position = 0.01;  ///< m
  double axis = 0.05;      ///< rad, between the end effector's z axis and the pose's
  /// m; spheres of two links may overlap this much before a solution counts
  /// as self-colliding: a mesh cover reaches up to its max_excess (2.5 cm by
  /// default) beyond the mesh, so touching spheres are not touching links.
  double self_overlap = 0.025;
};

/// Gives every goal and retreat of `graph` joint positions of the robot of
/// `planner` (size nq):
/// - joint positions of the robot's size are kept, unless a pose is given
///   beside them that they do not reach (GoalOptions): the pose wins;
/// - a pose is solved by Planner::SolveIkForToolAxis, seeded at the rest
///   task's solution (TaskGraph::rest, solved first from the middle of the
///   joint limits), with restarts drawn from a fixed seed, and the solution
///   must be clear of the planner's static scene (CalcClearance >= 0) and
///   of the arm itself (collision::SelfDistance over the link pairs
///   collision::ComputeSelfCollision finds worth checking, at least
///   -self_overlap);
/// - joint positions of another size with no pose are an error.
/// Returns one note per place whose joint positions were not used as
/// written. Deterministic. @throws std::invalid_argument naming the task
/// (no solution: the best position error and clearance).
std::vector<std::string> ResolveTaskGoals(const planning::Planner& planner, TaskGraph* graph,
                                          const GoalOptions& options = {});

/// The rest task's joint positions after ResolveTaskGoals; empty when the
/// graph names no rest task.
std::vector<double> RestPositions(const TaskGraph& graph);

}  // namespace iplan::supervisor
