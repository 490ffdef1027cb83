#include "collision_bound_cli.h"

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "iplan/collision/bound.h"

namespace iplan::collision {
namespace {

using nlohmann::json;

// A problem with one input line; the message names the offending value.
struct LineError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Invalid UTF-8 in echoed input is replaced rather than thrown on.
template <typename Json>
std::string SafeDump(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::string Dump(const json& j) {
  std::string s = SafeDump(j);
  return s.size() > 80 ? s.substr(0, 77) + "..." : s;
}

double Number(const json& obj, const char* key) {
  const json& v = obj.at(key);
  if (!v.is_number()) throw LineError(std::string("'") + key + "' must be a number, got " + Dump(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw LineError(std::string("'") + key + "' is not finite");
  return x;
}

template <size_t N>
std::array<double, N> Numbers(const json& obj, const char* key) {
  const json& v = obj.at(key);
  if (!v.is_array() || v.size() != N) {
    throw LineError(std::string("'") + key + "' must be an array of " + std::to_string(N) +
                    " numbers, got " + Dump(v));
  }
  std::array<double, N> out{};
  for (size_t i = 0; i < N; ++i) {
    if (!v[i].is_number()) {
      throw LineError(std::string("'") + key + "[" + std::to_string(i) + "]' must be a number, got " +
                      Dump(v[i]));
    }
    out[i] = v[i].get<double>();
    if (!std::isfinite(out[i])) {
      throw LineError(std::string("'") + key + "[" + std::to_string(i) + "]' is not finite");
    }
  }
  return out;
}

double Radius(const json& obj, const char* key) {
  const double r = Number(obj, key);
  if (r < 0.0) {
    std::ostringstream msg;
    msg << "'" << key << "' = " << r << " must be >= 0";
    throw LineError(msg.str());
  }
  return r;
}

nlohmann::ordered_json Evaluate(const std::string& line) {
  json obj;
  try {
    obj = json::parse(line);
  } catch (const json::exception& e) {  // parse_error, number overflow, ...
    throw LineError(std::string("invalid JSON: ") + e.what());
  }
  if (!obj.is_object()) throw LineError("expected a JSON object, got " + Dump(obj));
  for (const char* key : {"b", "r_robot", "mu", "sigma", "r_human"}) {
    if (!obj.contains(key)) throw LineError(std::string("missing key '") + key + "'");
  }
  for (const auto& item : obj.items()) {
    const std::string& k = item.key();
    if (k != "b" && k != "r_robot" && k != "mu" && k != "sigma" && k != "r_human") {
      throw LineError("unknown key '" + k + "'");
    }
  }
  const auto b = Numbers<3>(obj, "b");
  const auto mu = Numbers<3>(obj, "mu");
  const auto sig = Numbers<9>(obj, "sigma");
  const double r1 = Radius(obj, "r_robot");
  const double r2 = Radius(obj, "r_human");
  if (!(r1 + r2 > 0.0)) throw LineError("r_robot + r_human = 0 must be positive");
  Eigen::Matrix3d S;
  for (int i = 0; i < 9; ++i) S(i / 3, i % 3) = sig[i];
  const double scale = S.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      if (std::abs(S(i, j) - S(j, i)) > 1e-9 * scale) {
        std::ostringstream msg;
        msg.precision(17);
        msg << "'sigma' is not symmetric: sigma[" << i << "][" << j << "] = " << S(i, j)
            << " but sigma[" << j << "][" << i << "] = " << S(j, i);
        throw LineError(msg.str());
      }
    }
  }
  const Eigen::Matrix3d Ssym = 0.5 * (S + S.transpose());
  FactorizedGaussian g;
  if (!FactorizeGaussian(Eigen::Vector3d(mu[0], mu[1], mu[2]), Ssym, &g)) {
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                   Ssym, Eigen::EigenvaluesOnly).eigenvalues();
    std::ostringstream msg;
    msg << "'sigma' is not positive definite (eigenvalues " << ev[0] << ", " << ev[1] << ", "
        << ev[2] << ")";
    throw LineError(msg.str());
  }
  const PairBound pb = EvaluatePairBound(g, Eigen::Vector3d(b[0], b[1], b[2]), r1 + r2);
  // Keys in the documented order.
  nlohmann::ordered_json result;
  result["bound"] = pb.bound;
  result["x_max"] = {pb.x_max[0], pb.x_max[1], pb.x_max[2]};
  result["lambda"] = pb.lambda;
  return result;
}

}  // namespace

int RunCollisionBoundJsonLines(std::istream& in, std::ostream& out) {
  int failures = 0;
  int line_number = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      out << SafeDump(Evaluate(line)) << "\n";
    } catch (const LineError& e) {
      ++failures;
      out << SafeDump(json{{"error", "line " + std::to_string(line_number) + ": " + e.what()}})
          << "\n";
    }
  }
  out.flush();
  return failures;
}

}  // namespace iplan::collision
