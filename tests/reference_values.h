#pragma once
// Reference values for tests that guard "this change altered no result": a test adds the
// values it wants kept (integers and strings exactly, floating-point values with a
// tolerance) and compares them with a file under tests/data/reference/. Floating-point
// results that pass through libm, BLAS or LAPACK differ in their last bits between CPUs
// (FMA and plain variants, vector kernels chosen at run time), so they are never
// compared bit for bit against a typed-in value (docs/developing.md "Tests").
//
// The same object also keeps a digest of every value's exact bits (Bits()): record the
// values twice in one test and compare the two digests for determinism on one machine.
//
// HANDLABEL_WRITE_REFERENCES=1 rewrites the files from the code under test (review the
// diff before committing it).

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "formats/sha256.h"
#include "geometry/rigid3.h"

namespace handlabel::testing {

// Appends a matrix's entries row by row (independent of the storage order), for tests
// that pool related values into one array.
template <typename Derived>
void AppendValues(const Eigen::DenseBase<Derived>& m, std::vector<double>* out) {
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) out->push_back(double(m(r, c)));
  }
}
// Rotation (quaternion coefficients x, y, z, w), then translation.
inline void AppendValues(const Rigid3& t, std::vector<double>* out) {
  AppendValues(t.rotation.coeffs(), out);
  AppendValues(t.translation, out);
}
template <typename T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>
void AppendValues(const std::vector<T>& v, std::vector<double>* out) {
  out->insert(out->end(), v.begin(), v.end());
}

class ReferenceValues {
 public:
  // Values kept in tests/data/reference/<name>.txt, one line per value or array.
  explicit ReferenceValues(std::string name) : name_(std::move(name)) {}

  // An integer or string: must match exactly.
  template <typename T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
  ReferenceValues& Exact(const std::string& label, T v) {
    const int64_t wide = static_cast<int64_t>(v);
    bits_.Update(&wide, sizeof(wide));
    return AddExact(label, std::to_string(wide));
  }
  ReferenceValues& Exact(const std::string& label, const std::string& s);
  // Integer arrays (ids, faces, flags): length and a digest of the values, exactly.
  template <typename T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
  ReferenceValues& Exact(const std::string& label, const std::vector<T>& v) {
    return ExactInts(label, std::vector<int64_t>(v.begin(), v.end()));
  }

  // Floating-point values, within the tolerance of Compare(). Up to 12 values are kept
  // one by one, with max |x| as their scale; a longer array by its sum of |x| (the
  // scale) and four sums with pseudo-random +-1 weights, so that a change of any entry
  // by more than the tolerance times the scale is caught, not only a change of the
  // mean. The length and the count of infinities/NaNs are kept exactly.
  ReferenceValues& Near(const std::string& label, const std::vector<double>& v);
  ReferenceValues& Near(const std::string& label, double v) {
    return Near(label, std::vector<double>{v});
  }
  template <typename T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>
  ReferenceValues& Near(const std::string& label, const std::vector<T>& v) {
    return Near(label, std::vector<double>(v.begin(), v.end()));
  }
  template <typename Derived>
  ReferenceValues& Near(const std::string& label, const Eigen::DenseBase<Derived>& m) {
    std::vector<double> flat;
    AppendValues(m, &flat);
    return Near(label, flat);
  }
  ReferenceValues& Near(const std::string& label, const Rigid3& t) {
    std::vector<double> flat;
    AppendValues(t, &flat);
    return Near(label, flat);
  }

  // Every value against the file: exact entries equal, floating-point values within
  // abs_tol + rel_tol * scale. Names the first entries that differ. Writes the file
  // instead when HANDLABEL_WRITE_REFERENCES=1.
  ::testing::AssertionResult Compare(double abs_tol, double rel_tol) const;

  // A digest of the exact bits of every value added, in order: equal for two recordings
  // of the same computation on one machine. Never compare it with a typed-in value.
  std::string Bits() const;

  // The path of the reference file.
  std::string Path() const;

 private:
  struct Entry {
    std::string label;
    bool exact = true;
    std::string text;            // exact: the value; near: "<count> <non-finite>"
    double scale = 0;            // near
    std::vector<double> values;  // near
  };
  ReferenceValues& AddExact(const std::string& label, std::string text);
  ReferenceValues& ExactInts(const std::string& label, const std::vector<int64_t>& v);
  std::string Differs(const Entry& got, const Entry& want, double abs_tol,
                      double rel_tol) const;
  std::vector<Entry> ReadFile() const;
  void WriteFile() const;

  std::string name_;
  std::vector<Entry> entries_;
  Sha256 bits_;
};

}  // namespace handlabel::testing
