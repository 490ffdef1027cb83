// CDR (XCDR1, final extensibility: no DHEADER) of the plain iplan::msg types
// with Fast CDR, driven by FieldsOf<T>::Visit: one generic implementation for
// every generated type. The byte layout is the one fastddsgen's classes and
// idlc's types produce for our IDL subset (@final structs, unbounded
// sequences and strings, fixed arrays, primitives): primitives aligned to
// their size (8-byte types to 8) from the end of the encapsulation header,
// sequences and strings with a uint32 length (strings count their NUL).
// Internal to common/dds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

#include <fastcdr/Cdr.h>
#include <fastcdr/exceptions/NotEnoughMemoryException.h>

#include "iplan/msg/types.h"
#include "iplan/msg/visit.h"

namespace iplan::dds::fastdds_cdr {

using eprosima::fastcdr::Cdr;
using msg::internal::IsArray;
using msg::internal::IsVector;

/// fastddsgen's bounds for unbounded types in its maximum-size estimate.
constexpr std::size_t kMaxSizeSequenceLength = 100;
constexpr std::size_t kMaxSizeStringLength = 255;

/// Stream position (bytes from the alignment origin) after `v` written at `pos`.
template <class T>
std::size_t SizeAt(const T& v, std::size_t pos) {
  if constexpr (msg::kIsMessage<T>) {
    msg::FieldsOf<T>::Visit([&pos](const char*, const auto& f) { pos = SizeAt(f, pos); }, v);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    using E = typename T::value_type;
    if constexpr (IsVector<T>::value) pos += Cdr::alignment(pos, 4) + 4;
    if constexpr (std::is_arithmetic_v<E>) {
      if (!v.empty()) pos += Cdr::alignment(pos, sizeof(E)) + v.size() * sizeof(E);
    } else {
      for (const auto& e : v) pos = SizeAt(e, pos);
    }
  } else if constexpr (std::is_same_v<T, std::string>) {
    pos += Cdr::alignment(pos, 4) + 4 + v.size() + 1;
  } else {
    static_assert(std::is_arithmetic_v<T>, "unsupported field type");
    pos += Cdr::alignment(pos, sizeof(T)) + sizeof(T);
  }
  return pos;
}

/// Like SizeAt for the largest value of T as fastddsgen estimates it
/// (unbounded sequences of 100 elements, strings of 255 characters).
template <class T>
std::size_t MaxSizeAt(std::size_t pos) {
  if constexpr (msg::kIsMessage<T>) {
    const T sample{};
    msg::FieldsOf<T>::Visit(
        [&pos](const char*, const auto& f) { pos = MaxSizeAt<std::decay_t<decltype(f)>>(pos); }, sample);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    using E = typename T::value_type;
    std::size_t n = kMaxSizeSequenceLength;
    if constexpr (IsVector<T>::value) {
      pos += Cdr::alignment(pos, 4) + 4;
    } else {
      n = std::tuple_size<T>::value;
    }
    for (std::size_t i = 0; i < n; ++i) pos = MaxSizeAt<E>(pos);
  } else if constexpr (std::is_same_v<T, std::string>) {
    pos += Cdr::alignment(pos, 4) + 4 + kMaxSizeStringLength + 1;
  } else {
    pos += Cdr::alignment(pos, sizeof(T)) + sizeof(T);
  }
  return pos;
}

/// The fewest bytes a T can take on the wire (alignment ignored): bounds
/// the element count a sequence length may claim before anything is allocated.
template <class T>
std::size_t MinSize() {
  if constexpr (msg::kIsMessage<T>) {
    std::size_t n = 0;
    const T sample{};
    msg::FieldsOf<T>::Visit([&n](const char*, const auto& f) { n += MinSize<std::decay_t<decltype(f)>>(); },
                            sample);
    return n;
  } else if constexpr (IsVector<T>::value || std::is_same_v<T, std::string>) {
    return 4;
  } else if constexpr (IsArray<T>::value) {
    return std::tuple_size<T>::value * MinSize<typename T::value_type>();
  } else {
    return sizeof(T);
  }
}

/// Writes `v`; throws eprosima::fastcdr::exception::NotEnoughMemoryException
/// when the buffer is too small.
template <class T>
void Write(Cdr& cdr, const T& v) {
  if constexpr (msg::kIsMessage<T>) {
    msg::FieldsOf<T>::Visit([&cdr](const char*, const auto& f) { Write(cdr, f); }, v);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    using E = typename T::value_type;
    if constexpr (IsVector<T>::value) cdr << static_cast<uint32_t>(v.size());
    if constexpr (std::is_arithmetic_v<E>) {
      if (!v.empty()) cdr.serializeArray(v.data(), v.size());
    } else {
      for (const auto& e : v) Write(cdr, e);
    }
  } else {
    cdr << v;  // primitives; strings as their C string, like fastddsgen's classes
  }
}

/// Reading state: the stream and where the payload ends.
struct Source {
  Cdr& cdr;
  const char* end;
  std::size_t Remaining() { return static_cast<std::size_t>(end - cdr.getCurrentPosition()); }
};

/// Reads a sequence length that can still be satisfied by the bytes left
/// (each element taking at least `min_element` bytes), else throws.
inline uint32_t ReadLength(Source& in, std::size_t min_element) {
  uint32_t n = 0;
  in.cdr >> n;
  const std::size_t per = min_element == 0 ? 1 : min_element;
  if (n > in.Remaining() / per) {
    throw eprosima::fastcdr::exception::NotEnoughMemoryException(
        "sequence length larger than the rest of the sample");
  }
  return n;
}

/// Reads into `v`, overwriting every field; throws NotEnoughMemoryException
/// on a truncated sample or a length the sample cannot hold.
template <class T>
void Read(Source& in, T& v) {
  if constexpr (msg::kIsMessage<T>) {
    msg::FieldsOf<T>::Visit([&in](const char*, auto& f) { Read(in, f); }, v);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    using E = typename T::value_type;
    if constexpr (IsVector<T>::value) {
      static const std::size_t min_element = MinSize<E>();
      v.resize(ReadLength(in, min_element));
    }
    if constexpr (std::is_arithmetic_v<E>) {
      if (!v.empty()) in.cdr.deserializeArray(v.data(), v.size());
    } else {
      for (auto& e : v) Read(in, e);
    }
  } else {
    in.cdr >> v;
  }
}

}  // namespace iplan::dds::fastdds_cdr
