#include "tests/reference_values.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace handlabel::testing {
namespace {

// Arrays up to this length are kept entry by entry.
constexpr size_t kShortArray = 12;
constexpr int kWeightedSums = 4;

std::string Format(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

// +-1 from a 64-bit LCG (integers only: the same weights on every machine).
double Sign(uint64_t* state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (*state >> 63) ? 1.0 : -1.0;
}

bool WriteRequested() {
  const char* v = std::getenv("HANDLABEL_WRITE_REFERENCES");
  return v != nullptr && std::string(v) == "1";
}

}  // namespace

std::string ReferenceValues::Path() const {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/reference/" + name_ + ".txt";
}

std::string ReferenceValues::Bits() const {
  Sha256 copy = bits_;
  return copy.HexDigest();
}

ReferenceValues& ReferenceValues::AddExact(const std::string& label, std::string text) {
  Entry e;
  e.label = label;
  e.text = std::move(text);
  entries_.push_back(std::move(e));
  return *this;
}

ReferenceValues& ReferenceValues::Exact(const std::string& label, const std::string& s) {
  const uint64_t length = s.size();
  bits_.Update(&length, sizeof(length));
  bits_.Update(s);
  return AddExact(label, "\"" + s + "\"");
}

ReferenceValues& ReferenceValues::ExactInts(const std::string& label,
                                            const std::vector<int64_t>& v) {
  const uint64_t size = v.size();
  bits_.Update(&size, sizeof(size));
  bits_.Update(v.data(), v.size() * sizeof(int64_t));
  Sha256 sha;
  sha.Update(v.data(), v.size() * sizeof(int64_t));
  return AddExact(label, std::to_string(v.size()) + " " + sha.HexDigest().substr(0, 16));
}

ReferenceValues& ReferenceValues::Near(const std::string& label,
                                       const std::vector<double>& v) {
  const uint64_t size = v.size();
  bits_.Update(&size, sizeof(size));
  bits_.Update(v.data(), v.size() * sizeof(double));
  Entry e;
  e.label = label;
  e.exact = false;
  // Infinities (a depth buffer's background) are counted; the sums go over the rest.
  size_t non_finite = 0;
  double sum_abs = 0, max_abs = 0;
  for (double x : v) {
    if (!std::isfinite(x)) {
      ++non_finite;
      continue;
    }
    sum_abs += std::abs(x);
    max_abs = std::max(max_abs, std::abs(x));
  }
  e.text = std::to_string(v.size()) + " " + std::to_string(non_finite);
  if (v.size() <= kShortArray) {
    e.values = v;
    e.scale = max_abs;
  } else {
    e.values.push_back(sum_abs);
    uint64_t state = v.size();
    for (int k = 0; k < kWeightedSums; ++k) {
      double sum = 0;
      for (double x : v) {
        const double sign = Sign(&state);
        if (std::isfinite(x)) sum += sign * x;
      }
      e.values.push_back(sum);
    }
    e.scale = sum_abs;
  }
  entries_.push_back(std::move(e));
  return *this;
}

// Line format: label TAB "exact" TAB text, or label TAB "near" TAB "count non-finite"
// TAB scale TAB values separated by spaces.
void ReferenceValues::WriteFile() const {
  std::ofstream out(Path());
  out << "# Reference values of a test (tests/reference_values.h); rewrite with\n"
         "# HANDLABEL_WRITE_REFERENCES=1 and review the diff.\n";
  for (const Entry& e : entries_) {
    out << e.label << '\t' << (e.exact ? "exact" : "near") << '\t' << e.text;
    if (!e.exact) {
      out << '\t' << Format(e.scale) << '\t';
      for (size_t i = 0; i < e.values.size(); ++i) {
        out << (i ? " " : "") << Format(e.values[i]);
      }
    }
    out << '\n';
  }
}

std::vector<ReferenceValues::Entry> ReferenceValues::ReadFile() const {
  std::ifstream in(Path());
  std::vector<Entry> entries;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    Entry e;
    std::string kind, scale, values;
    std::getline(fields, e.label, '\t');
    std::getline(fields, kind, '\t');
    std::getline(fields, e.text, '\t');
    e.exact = kind == "exact";
    if (!e.exact) {
      std::getline(fields, scale, '\t');
      std::getline(fields, values, '\t');
      e.scale = std::strtod(scale.c_str(), nullptr);
      std::istringstream numbers(values);
      for (std::string n; numbers >> n;)
        e.values.push_back(std::strtod(n.c_str(), nullptr));
    }
    entries.push_back(std::move(e));
  }
  return entries;
}

// "" when `got` matches `want`, else what differs.
std::string ReferenceValues::Differs(const Entry& got, const Entry& want, double abs_tol,
                                     double rel_tol) const {
  if (got.label != want.label || got.exact != want.exact || got.text != want.text ||
      got.values.size() != want.values.size()) {
    return want.label + ": reference " + want.text + ", got " + got.label + " " +
           got.text;
  }
  const double tol = abs_tol + rel_tol * std::max(got.scale, want.scale);
  for (size_t i = 0; i < got.values.size(); ++i) {
    const double diff = std::abs(got.values[i] - want.values[i]);
    // Equal infinities pass; NaN never does.
    if (!(got.values[i] == want.values[i] || diff <= tol)) {
      return want.label + "[" + std::to_string(i) + "]: reference " +
             Format(want.values[i]) + ", got " + Format(got.values[i]) + " (|diff| " +
             Format(diff) + " > " + Format(tol) + ")";
    }
  }
  return "";
}

::testing::AssertionResult ReferenceValues::Compare(double abs_tol,
                                                    double rel_tol) const {
  if (WriteRequested()) {
    WriteFile();
    return ::testing::AssertionSuccess() << "wrote " << Path();
  }
  const std::vector<Entry> expected = ReadFile();
  if (expected.empty()) {
    return ::testing::AssertionFailure()
           << Path() << ": no reference values (write them with "
           << "HANDLABEL_WRITE_REFERENCES=1 and review the diff)";
  }
  if (expected.size() != entries_.size()) {
    return ::testing::AssertionFailure() << Path() << ": " << expected.size()
                                         << " entries, the test gave " << entries_.size();
  }
  int differ = 0;
  std::ostringstream report;
  for (size_t i = 0; i < entries_.size(); ++i) {
    const std::string problem = Differs(entries_[i], expected[i], abs_tol, rel_tol);
    if (!problem.empty() && ++differ <= 5) report << "\n  " << problem;
  }
  if (differ == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << Path() << ": " << differ << " of " << entries_.size() << " entries differ"
         << report.str();
}

}  // namespace handlabel::testing
