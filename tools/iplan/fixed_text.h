// A number as the iplan tool prints it: fixed-point with a given number of
// decimals ("inf" for an infinity).
#pragma once

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace iplan::cli {

inline std::string Fixed(double v, int digits) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace iplan::cli
