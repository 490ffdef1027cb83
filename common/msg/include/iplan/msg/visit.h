// Generic algorithms over every generated message type, built on
// FieldsOf<T>::Visit: field-by-field comparison, finiteness checks and seeded
// random filling (for tests). Header-only; allocation only where stated.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "iplan/msg/types.h"

namespace iplan::msg {
namespace internal {

template <class T>
struct IsVector : std::false_type {};
template <class T, class A>
struct IsVector<std::vector<T, A>> : std::true_type {};
template <class T>
struct IsArray : std::false_type {};
template <class T, std::size_t N>
struct IsArray<std::array<T, N>> : std::true_type {};

template <class T>
void CompareValue(const std::string& path, const T& a, const T& b, std::optional<std::string>* diff);

template <class T>
void CompareValue(const std::string& path, const T& a, const T& b, std::optional<std::string>* diff) {
  if (*diff) return;
  if constexpr (kIsMessage<T>) {
    FieldsOf<T>::Visit(
        [&](const char* name, const auto& fa, const auto& fb) {
          CompareValue(path.empty() ? std::string(name) : path + "." + name, fa, fb, diff);
        },
        a, b);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    if (a.size() != b.size()) {
      *diff = path + ": length " + std::to_string(a.size()) + " != " + std::to_string(b.size());
      return;
    }
    for (std::size_t i = 0; i < a.size() && !*diff; ++i) {
      CompareValue(path + "[" + std::to_string(i) + "]", a[i], b[i], diff);
    }
  } else if constexpr (std::is_floating_point_v<T>) {
    // Bit-level equality, NaN equal to NaN: a round trip must not change a value.
    const bool same = (a == b && std::signbit(a) == std::signbit(b)) || (std::isnan(a) && std::isnan(b));
    if (!same) *diff = path + ": " + std::to_string(a) + " != " + std::to_string(b);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (a != b) *diff = path + ": \"" + a + "\" != \"" + b + "\"";
  } else {
    if (a != b) *diff = path + ": " + std::to_string(+a) + " != " + std::to_string(+b);
  }
}

template <class T>
void FindNonFiniteValue(const std::string& path, const T& v, std::optional<std::string>* where) {
  if (*where) return;
  if constexpr (kIsMessage<T>) {
    FieldsOf<T>::Visit(
        [&](const char* name, const auto& f) {
          FindNonFiniteValue(path.empty() ? std::string(name) : path + "." + name, f, where);
        },
        v);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    using E = typename T::value_type;
    if constexpr (std::is_floating_point_v<E> || kIsMessage<E>) {
      for (std::size_t i = 0; i < v.size() && !*where; ++i) {
        FindNonFiniteValue(path + "[" + std::to_string(i) + "]", v[i], where);
      }
    }
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(v)) *where = path;
  }
}

// Allocation-free scan: true when every floating-point field is finite.
// (Measured: a predictable branch per value beats branch-free variants here.)
template <class T>
bool AllFiniteValue(const T& v) {
  if constexpr (kIsMessage<T>) {
    bool ok = true;
    FieldsOf<T>::Visit([&ok](const char*, const auto& f) { ok = ok && AllFiniteValue(f); }, v);
    return ok;
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    using E = typename T::value_type;
    if constexpr (std::is_floating_point_v<E> || kIsMessage<E>) {
      for (const auto& e : v) {
        if (!AllFiniteValue(e)) return false;
      }
    }
    return true;
  } else if constexpr (std::is_floating_point_v<T>) {
    return std::isfinite(v);
  } else {
    return true;
  }
}

template <class T, class Rng>
void FillRandomValue(T& v, Rng& rng, int depth) {
  if constexpr (kIsMessage<T>) {
    FieldsOf<T>::Visit([&](const char*, auto& f) { FillRandomValue(f, rng, depth + 1); }, v);
  } else if constexpr (IsVector<T>::value) {
    std::uniform_int_distribution<int> len(0, depth > 2 ? 3 : 6);
    v.resize(static_cast<std::size_t>(len(rng)));
    for (auto& e : v) FillRandomValue(e, rng, depth + 1);
  } else if constexpr (IsArray<T>::value) {
    for (auto& e : v) FillRandomValue(e, rng, depth + 1);
  } else if constexpr (std::is_same_v<T, std::string>) {
    std::uniform_int_distribution<int> len(0, 12);
    std::uniform_int_distribution<int> ch('a', 'z');
    v.assign(static_cast<std::size_t>(len(rng)), 'x');
    for (auto& c : v) c = static_cast<char>(ch(rng));
  } else if constexpr (std::is_same_v<T, bool>) {
    v = std::bernoulli_distribution(0.5)(rng);
  } else if constexpr (std::is_floating_point_v<T>) {
    v = static_cast<T>(std::uniform_real_distribution<double>(-1e3, 1e3)(rng));
  } else {
    v = static_cast<T>(std::uniform_int_distribution<long long>(
        static_cast<long long>(std::numeric_limits<T>::min()),
        static_cast<long long>(std::numeric_limits<T>::max() / 2))(rng));
  }
}

}  // namespace internal

/// The path of the first field where `a` and `b` differ ("joints[2].position.x:
/// 1 != 2"), or nullopt when they are equal field by field. Floating-point
/// fields compare by value (NaN equals NaN). Allocates strings.
template <class T>
std::optional<std::string> FirstDifference(const T& a, const T& b) {
  static_assert(kIsMessage<T>, "FirstDifference takes a message type");
  std::optional<std::string> diff;
  internal::CompareValue(std::string(), a, b, &diff);
  return diff;
}

/// The path of the first NaN or infinite floating-point field of `m`
/// ("joints[0].position.z"), or nullopt when every number is finite.
template <class T>
std::optional<std::string> FindNonFinite(const T& m) {
  static_assert(kIsMessage<T>, "FindNonFinite takes a message type");
  if (internal::AllFiniteValue(m)) return std::nullopt;  // the common case allocates nothing
  std::optional<std::string> where;
  internal::FindNonFiniteValue(std::string(), m, &where);
  return where;
}

/// Fills every field of `m` with random values from `rng` (sequences of 0-6
/// elements, strings of 0-12 letters). For round-trip tests; seed `rng`.
template <class T, class Rng>
void FillRandom(T& m, Rng& rng) {
  static_assert(kIsMessage<T>, "FillRandom takes a message type");
  internal::FillRandomValue(m, rng, 0);
}

}  // namespace iplan::msg
