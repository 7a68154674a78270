#pragma once
// A digest of exact values (the bit patterns of doubles and floats, integers, strings)
// for tests that pin a function's output: any change in any bit changes the digest, so
// restructuring code cannot change results unnoticed. Record the digest once from the
// code under test; a new digest means the numbers changed.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "core/rigid3.h"
#include "core/sha256.h"

namespace handlabel::testing {

class PinDigest {
 public:
  PinDigest& Add(double v) { return Bytes(&v, sizeof(v)); }
  PinDigest& Add(float v) { return Bytes(&v, sizeof(v)); }
  template <typename T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
  PinDigest& Add(T v) {
    const int64_t wide = static_cast<int64_t>(v);
    return Bytes(&wide, sizeof(wide));
  }
  PinDigest& Add(const std::string& s) {
    Add(s.size());
    return Bytes(s.data(), s.size());
  }
  PinDigest& Add(const char* s) { return Add(std::string(s ? s : "(null)")); }
  // Shape, then the entries rounded to multiples of `quantum`, row by row: for values
  // whose last bits legitimately vary between machines.
  template <typename Derived>
  PinDigest& AddRounded(const Eigen::DenseBase<Derived>& m, double quantum) {
    Add(m.rows()).Add(m.cols());
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) {
        Add(static_cast<int64_t>(std::llround(m(r, c) / quantum)));
      }
    }
    return *this;
  }
  // Shape, then the entries row by row (independent of the storage order).
  template <typename Derived>
  PinDigest& Add(const Eigen::DenseBase<Derived>& m) {
    Add(m.rows()).Add(m.cols());
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) Add(m(r, c));
    }
    return *this;
  }
  PinDigest& Add(const Rigid3& t) { return Add(t.rotation.coeffs()).Add(t.translation); }
  template <typename T>
  PinDigest& Add(const std::vector<T>& values) {
    Add(values.size());
    for (const T& v : values) Add(v);
    return *this;
  }
  template <typename K, typename V>
  PinDigest& Add(const std::map<K, V>& values) {
    Add(values.size());
    for (const auto& [k, v] : values) Add(k).Add(v);
    return *this;
  }
  // The first 16 hex digits of the SHA-256 of everything added.
  std::string Hex() { return sha_.HexDigest().substr(0, 16); }

 private:
  PinDigest& Bytes(const void* data, size_t size) {
    sha_.Update(data, size);
    return *this;
  }
  Sha256 sha_;
};

}  // namespace handlabel::testing
