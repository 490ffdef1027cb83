#include "split_segments.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

namespace iplan::cloud::internal {
namespace {

// Border lengths between fragments of one geometric segment, by 4-neighbour
// pixel pairs.
std::unordered_map<std::uint64_t, int> Borders(int width, int height, const std::vector<int>& geometric,
                                               const std::vector<int>& fragments) {
  std::unordered_map<std::uint64_t, int> borders;
  auto add = [&](int i, int j) {
    const int a = fragments[i], b = fragments[j];
    if (a < 0 || b < 0 || a == b || geometric[i] != geometric[j]) return;
    ++borders[(static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b))];
  };
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const int i = r * width + c;
      if (c + 1 < width) add(i, i + 1);
      if (r + 1 < height) add(i, i + width);
    }
  return borders;
}

}  // namespace

std::vector<int> SplitSegments(int width, int height, const std::vector<int>& geometric,
                               const std::vector<int>& fragments, int min_core,
                               const std::vector<std::uint8_t>& may_core) {
  int nf = 0, ng = 0;
  for (std::size_t i = 0; i < fragments.size(); ++i) {
    nf = std::max(nf, fragments[i] + 1);
    ng = std::max(ng, geometric[i] + 1);
  }
  std::vector<int> size(nf, 0), geo_of(nf, -1);
  for (std::size_t i = 0; i < fragments.size(); ++i)
    if (fragments[i] >= 0) {
      ++size[fragments[i]];
      geo_of[fragments[i]] = geometric[i];
    }
  std::vector<int> cores(ng, 0), largest(ng, -1);
  auto core = [&](int f) { return size[f] >= min_core && may_core[f]; };
  for (int f = 0; f < nf; ++f) {
    const int g = geo_of[f];
    if (g < 0) continue;
    if (core(f)) ++cores[g];
    if (largest[g] < 0 || size[f] > size[largest[g]]) largest[g] = f;
  }
  // owner[f]: the final segment of fragment f (a fragment id), -1 = not yet.
  std::vector<int> owner(nf, -1);
  bool any_split = false;
  for (int f = 0; f < nf; ++f) {
    const int g = geo_of[f];
    if (g < 0) continue;
    if (cores[g] < 2) owner[f] = largest[g];
    else if (core(f)) owner[f] = f;
    else any_split = true;
  }
  if (any_split) {
    const auto borders = Borders(width, height, geometric, fragments);
    for (int pass = 0; pass < 16; ++pass) {
      // best[f] = (border length, owner) of the assigned neighbour bordering f most.
      std::vector<std::pair<int, int>> best(nf, {0, -1});
      for (const auto& [key, length] : borders) {
        const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
        if (owner[a] < 0 && owner[b] >= 0 && length > best[a].first) best[a] = {length, owner[b]};
        if (owner[b] < 0 && owner[a] >= 0 && length > best[b].first) best[b] = {length, owner[a]};
      }
      bool changed = false;
      for (int f = 0; f < nf; ++f)
        if (owner[f] < 0 && best[f].second >= 0) {
          owner[f] = best[f].second;
          changed = true;
        }
      if (!changed) break;
    }
    // Cut off from every core: the largest core of its geometric segment.
    std::vector<int> largest_core(ng, -1);
    for (int f = 0; f < nf; ++f) {
      const int g = geo_of[f];
      if (g >= 0 && owner[f] == f && (largest_core[g] < 0 || size[f] > size[largest_core[g]])) largest_core[g] = f;
    }
    for (int f = 0; f < nf; ++f)
      if (owner[f] < 0 && geo_of[f] >= 0) owner[f] = largest_core[geo_of[f]];
  }
  std::vector<int> out(fragments.size(), -1);
  for (std::size_t i = 0; i < fragments.size(); ++i)
    if (fragments[i] >= 0) out[i] = owner[fragments[i]];
  return out;
}

}  // namespace iplan::cloud::internal
