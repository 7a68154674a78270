#pragma once
// Reference values for tests that guard "this change altered no result": a test adds the
// values it wants kept (integers and strings exactly, floating-point values with a
// tolerance) and compares them with a file under tests/data/reference/. Floating-point
// results that pass through libm, BLAS or LAPACK differ in their last bits between CPUs
// (FMA and plain variants, vector kernels chosen at run time), so they are never
// compared bit for bit against a typed-in value; determinism on one machine is tested by
// computing twice and comparing bits instead (docs/developing.md "Tests").
//
// The same object also keeps a digest of every value's exact bits (Bits()): record the
// values twice in one test and compare the two digests for determinism.
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

class ReferenceValues {
 public:
  // Values kept in tests/data/reference/<name>.txt.
  explicit ReferenceValues(std::string name) : name_(std::move(name)) {}

  // An integer or string: must match exactly.
  template <typename T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
  ReferenceValues& Exact(const std::string& label, T v) {
    const int64_t wide = static_cast<int64_t>(v);
    bits_.Update(&wide, sizeof(wide));
    return AddEntry(label, Entry::kExact, std::to_string(wide), 0, 0);
  }
  ReferenceValues& Exact(const std::string& label, const std::string& s);

  // A floating-point value: must match within the tolerance of Compare().
  ReferenceValues& Near(const std::string& label, double v);

  // An array of floating-point values: its length exactly, then every entry of an array
  // of up to 12; a long one by its sum of |x| and eight sums with pseudo-random +-1
  // weights, each within tolerance * sum |x| (so a change of any entry by more than the
  // tolerance times the array's scale is caught, not only a change of the mean).
  ReferenceValues& Near(const std::string& label, const double* data, size_t size);
  ReferenceValues& Near(const std::string& label, const std::vector<double>& v) {
    return Near(label, v.data(), v.size());
  }
  ReferenceValues& Near(const std::string& label, const std::vector<float>& v);
  template <typename Derived>
  ReferenceValues& Near(const std::string& label, const Eigen::DenseBase<Derived>& m) {
    // Row by row, independent of the storage order.
    std::vector<double> flat;
    flat.reserve(static_cast<size_t>(m.size()));
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) flat.push_back(double(m(r, c)));
    }
    Exact(label + ".rows", m.rows());
    return Near(label, flat);
  }
  // Rotation (quaternion coefficients x, y, z, w) and translation.
  ReferenceValues& Near(const std::string& label, const Rigid3& t) {
    return Near(label + ".rotation", t.rotation.coeffs())
        .Near(label + ".translation", t.translation);
  }
  // Integer arrays (ids, masks, counts): length and a digest of the values, exactly.
  template <typename T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
  ReferenceValues& Exact(const std::string& label, const std::vector<T>& v) {
    std::vector<int64_t> wide(v.begin(), v.end());
    return ExactInts(label, wide);
  }

  // Every value against the file: exact entries equal, floating-point entries within
  // abs_tol + rel_tol * scale. Names the first entries that differ. Writes the file
  // instead when HANDLABEL_WRITE_REFERENCES=1.
  ::testing::AssertionResult Compare(double abs_tol, double rel_tol) const;

  // The path of the reference file.
  std::string Path() const;

  // A digest of the exact bits of every value added, in order: equal for two recordings
  // of the same computation on one machine. Never compare it with a typed-in value.
  std::string Bits() const;

 private:
  struct Entry {
    enum Kind { kExact, kNear };
    std::string label;
    Kind kind;
    std::string text;  // exact value, as written
    double value;      // kNear
    double scale;      // kNear: |value|, or sum |x| for a long array's sums
  };
  ReferenceValues& AddEntry(const std::string& label, Entry::Kind kind, std::string text,
                            double value, double scale);
  ReferenceValues& ExactInts(const std::string& label, const std::vector<int64_t>& v);
  std::vector<Entry> ReadFile() const;
  void WriteFile() const;

  std::string name_;
  std::vector<Entry> entries_;
  Sha256 bits_;
};

}  // namespace handlabel::testing
