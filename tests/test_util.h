#pragma once
// Shared test helpers: a per-test seeded random generator and matchers for matrices
// and rigid transforms.

#include <gmock/gmock.h>

#include <Eigen/Core>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "core/random.h"
#include "geometry/rigid3.h"

namespace handlabel::testing {

// Re-seeded before every test from the test's full name (see tests/main.cc), so a
// failure reproduces when the test runs alone.
std::mt19937_64& TestRng();
uint64_t TestSeed();

// A fresh, empty folder for the running test, unique per test name and process, so
// tests that ctest runs in parallel never share files. Removed when the test passes
// (and at the next call for the same test); left behind after a failure for inspection.
std::string ScratchDir();

// The message of the InputError `f` throws, or "(no InputError)": for asserting that an
// error names the file, field and expectation.
inline std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// The bytes of a file ("" if it cannot be read).
std::string ReadFileBytes(const std::string& path);

// Every regular file under `dir` (path relative to `dir` -> bytes); empty if `dir` does
// not exist. For comparing whole output folders.
std::map<std::string, std::string> FilesUnder(const std::string& dir);

inline double Uniform(double lo, double hi) {
  return handlabel::Uniform(TestRng(), lo, hi);
}
inline double Gaussian(double sigma) { return handlabel::Gaussian(TestRng(), sigma); }
inline Eigen::Vector3d RandomVector3(double lo, double hi) {
  return {Uniform(lo, hi), Uniform(lo, hi), Uniform(lo, hi)};
}
inline Eigen::Quaterniond RandomRotation() {
  Eigen::Vector4d q(Gaussian(1), Gaussian(1), Gaussian(1), Gaussian(1));
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
}

// Elementwise |a - b| <= tol, with the worst entry named in the explanation.
MATCHER_P2(MatrixNear, expected, tol, "") {
  const Eigen::MatrixXd a = arg;
  const Eigen::MatrixXd b = expected;
  if (a.rows() != b.rows() || a.cols() != b.cols()) {
    *result_listener << "shape " << a.rows() << "x" << a.cols() << " vs " << b.rows()
                     << "x" << b.cols();
    return false;
  }
  if (a.size() == 0) return true;
  Eigen::Index r, c;
  const double worst = (a - b).cwiseAbs().maxCoeff(&r, &c);
  if (!(worst <= tol)) {
    *result_listener << "largest difference " << worst << " at (" << r << "," << c
                     << "): " << a(r, c) << " vs " << b(r, c);
    return false;
  }
  return true;
}

// Rotation angle within rot_tol_rad and translation distance within trans_tol.
MATCHER_P3(Rigid3Near, expected, rot_tol_rad, trans_tol, "") {
  const double angle = ::handlabel::RotationAngleBetween(arg, expected);
  const double dist = (arg.translation - expected.translation).norm();
  if (!(angle <= rot_tol_rad) || !(dist <= trans_tol)) {
    *result_listener << "rotation differs by " << angle << " rad, translation by "
                     << dist;
    return false;
  }
  return true;
}

}  // namespace handlabel::testing
