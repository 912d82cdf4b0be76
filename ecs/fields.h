#pragma once
// Field visitors. Every component lists its state once, in
//   template <class V> void visitFields(V& v) { v("mass", mass); v("position", x); ... }
// and that single list drives checkpoint writing/reading and the finiteness guard, so a new
// field cannot be forgotten by one of them.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "ecs/binary_io.h"

namespace monolith {

template <class T>
struct IsEigenDense : std::is_base_of<Eigen::DenseBase<T>, T> {};
template <class T>
struct IsStdVector : std::false_type {};
template <class T, class A>
struct IsStdVector<std::vector<T, A>> : std::true_type {};

struct FieldWriter {
  BinaryWriter& out;
  template <class T>
  void operator()(const char*, const T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      out.string(value);
    } else if constexpr (IsStdVector<T>::value) {
      out.vector(value);  // bulk arrays (grid faces, cells, particles): one component, many values
    } else if constexpr (std::is_same_v<T, Eigen::Quaterniond>) {
      out.raw(value.coeffs().data(), 4 * sizeof(double));
    } else if constexpr (IsEigenDense<T>::value) {
      static_assert(T::SizeAtCompileTime > 0, "fields must be fixed-size Eigen objects");
      out.raw(value.data(), sizeof(typename T::Scalar) * T::SizeAtCompileTime);
    } else {
      out.pod(value);
    }
  }
};

struct FieldReader {
  BinaryReader& in;
  template <class T>
  void operator()(const char*, T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      value = in.string();
    } else if constexpr (IsStdVector<T>::value) {
      value = in.template vector<typename T::value_type>();
    } else if constexpr (std::is_same_v<T, Eigen::Quaterniond>) {
      in.raw(value.coeffs().data(), 4 * sizeof(double));
    } else if constexpr (IsEigenDense<T>::value) {
      in.raw(value.data(), sizeof(typename T::Scalar) * T::SizeAtCompileTime);
    } else {
      value = in.template pod<T>();
    }
  }
};

// A component's saved layout as text, one "name:kind" per field in visit order ("s" string,
// "v<bytes>" vector of elements of that size, "q" quaternion, "e<bytes>" fixed Eigen object,
// "p<bytes>" plain value). Checkpoints store it beside each pool, so that a file written by a
// build whose component had other fields is refused by name instead of being misread.
struct FieldLayoutWriter {
  std::string layout;
  template <class T>
  void operator()(const char* name, const T&) {
    std::string kind;
    if constexpr (std::is_same_v<T, std::string>) {
      kind = "s";
    } else if constexpr (IsStdVector<T>::value) {
      kind = "v" + std::to_string(sizeof(typename T::value_type));
    } else if constexpr (std::is_same_v<T, Eigen::Quaterniond>) {
      kind = "q";
    } else if constexpr (IsEigenDense<T>::value) {
      kind = "e" + std::to_string(sizeof(typename T::Scalar) * T::SizeAtCompileTime);
    } else {
      kind = "p" + std::to_string(sizeof(T));
    }
    if (!layout.empty()) layout += ' ';
    layout += std::string(name) + ":" + kind;
  }
};

// The first non-finite or absurdly large floating-point value, with the field's name and
// the index inside the field (for vectors/matrices).
struct FieldViolation {
  std::string field;
  int index = 0;
  double value = 0;
};

struct FieldSanityChecker {
  double maxAbs;
  std::optional<FieldViolation> found;
  void check(const char* name, int index, double v) {
    if (found) return;
    if (!std::isfinite(v) || std::abs(v) > maxAbs) found = FieldViolation{name, index, v};
  }
  template <class T>
  void operator()(const char* name, const T& value) {
    if constexpr (IsStdVector<T>::value) {
      if constexpr (std::is_floating_point_v<typename T::value_type>)
        for (std::size_t i = 0; i < value.size(); ++i) check(name, static_cast<int>(i), value[i]);
    } else if constexpr (std::is_same_v<T, Eigen::Quaterniond>) {
      for (int i = 0; i < 4; ++i) check(name, i, value.coeffs()[i]);
    } else if constexpr (IsEigenDense<T>::value) {
      if constexpr (std::is_floating_point_v<typename T::Scalar>)
        for (int i = 0; i < int(T::SizeAtCompileTime); ++i) check(name, i, value.data()[i]);
    } else if constexpr (std::is_floating_point_v<T>) {
      check(name, 0, value);
    }
  }
};

}  // namespace monolith
