// The logic of `iplan collision-bound`: JSON lines in, JSON lines out.
#pragma once

#include <istream>
#include <ostream>

namespace iplan::collision {

/// Reads JSON lines from `in`, each
///   {"b":[x,y,z],"r_robot":r1,"mu":[x,y,z],"sigma":[9 numbers, row-major],
///    "r_human":r2}
/// (b, mu in m, world frame; sigma in m^2; radii in m), and writes one line
/// per input to `out`:
///   {"bound":p,"x_max":[x,y,z],"lambda":l}   (lambda 0 when mu is inside the ball)
/// or, for a bad line, {"error":"line N: <problem with the offending value>"}:
/// invalid JSON, not an object, missing or unknown key, wrong type or length,
/// non-finite number, negative radius, r_robot + r_human not positive, sigma
/// not symmetric (relative tolerance 1e-9) or not positive definite. Blank lines
/// are skipped (but counted in line numbers); processing continues after a bad
/// line. Numbers are written with round-trip precision.
/// @returns the number of bad lines.
/// Thread-safe for distinct streams; allocates.
int RunCollisionBoundJsonLines(std::istream& in, std::ostream& out);

}  // namespace iplan::collision
