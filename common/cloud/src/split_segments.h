// Splitting geometric segments into parts along creases (internal).
#pragma once

#include <cstdint>
#include <vector>

namespace iplan::cloud::internal {

/// Combines two labelings of one width x height image (-1 = no segment):
/// `geometric` (segments by 3D gaps) and `fragments` (finer: every fragment
/// lies inside one geometric segment). A fragment is a core when it has at
/// least `min_core` pixels and may_core[fragment] is set. A geometric
/// segment holding at least two cores is split into them: every other
/// fragment joins the core it borders most (through other such fragments
/// when it borders none), or the largest core when it is cut off from all.
/// Other geometric segments stay whole. Returns the final segment per pixel
/// (-1 = none; a part is numbered as one of its fragments). may_core has one entry per
/// fragment id. Allocates.
std::vector<int> SplitSegments(int width, int height, const std::vector<int>& geometric,
                               const std::vector<int>& fragments, int min_core,
                               const std::vector<std::uint8_t>& may_core);

}  // namespace iplan::cloud::internal
