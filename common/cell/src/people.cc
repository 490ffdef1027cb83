#include "iplan/cell/people.h"

#include <algorithm>

namespace iplan::cell {

double UnionBound(const std::vector<double>& per_person) {
  double sum = 0;
  for (double p : per_person) sum += std::max(0.0, p);
  return std::min(1.0, sum);
}

}  // namespace iplan::cell
