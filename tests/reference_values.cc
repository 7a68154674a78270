#include "tests/reference_values.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "formats/sha256.h"

namespace handlabel::testing {
namespace {

// Arrays up to this length are kept entry by entry.
constexpr size_t kShortArray = 12;
constexpr int kWeightedSums = 8;

std::string Format(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

// +-1 from a 64-bit LCG (integers only, the same on every machine).
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

ReferenceValues& ReferenceValues::AddEntry(const std::string& label, Entry::Kind kind,
                                           std::string text, double value, double scale) {
  entries_.push_back({label, kind, std::move(text), value, scale});
  return *this;
}

std::string ReferenceValues::Bits() const {
  Sha256 copy = bits_;
  return copy.HexDigest();
}

ReferenceValues& ReferenceValues::Exact(const std::string& label, const std::string& s) {
  const uint64_t length = s.size();
  bits_.Update(&length, sizeof(length));
  bits_.Update(s);
  return AddEntry(label, Entry::kExact, "\"" + s + "\"", 0, 0);
}

ReferenceValues& ReferenceValues::Near(const std::string& label, double v) {
  bits_.Update(&v, sizeof(v));
  return AddEntry(label, Entry::kNear, Format(v), v, std::abs(v));
}

ReferenceValues& ReferenceValues::Near(const std::string& label, const double* data,
                                       size_t size) {
  Exact(label + ".size", size);
  if (size <= kShortArray) {
    // Near(double) adds each entry's bits.
    for (size_t i = 0; i < size; ++i)
      Near(label + "[" + std::to_string(i) + "]", data[i]);
    return *this;
  }
  bits_.Update(data, size * sizeof(double));
  // Infinities (a depth buffer's background) are counted, the sums go over the rest.
  int64_t non_finite = 0;
  double sum_abs = 0;
  for (size_t i = 0; i < size; ++i) {
    if (std::isfinite(data[i])) {
      sum_abs += std::abs(data[i]);
    } else {
      ++non_finite;
    }
  }
  AddEntry(label + ".non_finite", Entry::kExact, std::to_string(non_finite), 0, 0);
  AddEntry(label + ".sum_abs", Entry::kNear, Format(sum_abs), sum_abs, sum_abs);
  uint64_t state = size;
  for (int k = 0; k < kWeightedSums; ++k) {
    double sum = 0;
    for (size_t i = 0; i < size; ++i) {
      const double sign = Sign(&state);
      if (std::isfinite(data[i])) sum += sign * data[i];
    }
    AddEntry(label + ".weighted_sum" + std::to_string(k), Entry::kNear, Format(sum), sum,
             sum_abs);
  }
  return *this;
}

ReferenceValues& ReferenceValues::Near(const std::string& label,
                                       const std::vector<float>& v) {
  const std::vector<double> wide(v.begin(), v.end());
  return Near(label, wide);
}

ReferenceValues& ReferenceValues::ExactInts(const std::string& label,
                                            const std::vector<int64_t>& v) {
  Exact(label + ".size", v.size());
  bits_.Update(v.data(), v.size() * sizeof(int64_t));
  Sha256 sha;
  sha.Update(v.data(), v.size() * sizeof(int64_t));
  return AddEntry(label + ".sha256", Entry::kExact, sha.HexDigest().substr(0, 16), 0, 0);
}

void ReferenceValues::WriteFile() const {
  std::ofstream out(Path());
  out << "# Reference values of a test (tests/reference_values.h); rewrite with\n"
         "# HANDLABEL_WRITE_REFERENCES=1 and review the diff.\n";
  for (const Entry& e : entries_) {
    out << e.label << '\t' << (e.kind == Entry::kExact ? "exact" : "near") << '\t'
        << e.text;
    if (e.kind == Entry::kNear) out << '\t' << Format(e.scale);
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
    std::string kind;
    std::getline(fields, e.label, '\t');
    std::getline(fields, kind, '\t');
    std::getline(fields, e.text, '\t');
    e.kind = kind == "exact" ? Entry::kExact : Entry::kNear;
    e.value = e.kind == Entry::kNear ? std::strtod(e.text.c_str(), nullptr) : 0;
    std::string scale;
    std::getline(fields, scale, '\t');
    e.scale = scale.empty() ? 0 : std::strtod(scale.c_str(), nullptr);
    entries.push_back(e);
  }
  return entries;
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
                                         << " values, the test gave " << entries_.size();
  }
  int differ = 0;
  std::ostringstream report;
  for (size_t i = 0; i < entries_.size(); ++i) {
    const Entry& got = entries_[i];
    const Entry& want = expected[i];
    bool same = got.label == want.label && got.kind == want.kind;
    double diff = 0, tol = 0;
    if (same && got.kind == Entry::kExact) same = got.text == want.text;
    if (same && got.kind == Entry::kNear) {
      diff = std::abs(got.value - want.value);
      tol = abs_tol + rel_tol * std::max(got.scale, want.scale);
      same = got.value == want.value || diff <= tol;  // equal infinities; NaN differs
    }
    if (!same && ++differ <= 5) {
      report << "\n  " << want.label << ": reference " << want.text << ", got "
             << got.label << " " << got.text;
      if (got.kind == Entry::kNear) report << " (|diff| " << diff << " > " << tol << ")";
    }
  }
  if (differ == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << Path() << ": " << differ << " of " << entries_.size() << " values differ"
         << report.str();
}

}  // namespace handlabel::testing
