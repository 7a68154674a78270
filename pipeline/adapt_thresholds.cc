#include "pipeline/adapt_thresholds.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace handlabel {
namespace {

struct Tunable {
  const char* check;
  double QualityThresholds::*threshold;
};

constexpr Tunable kTunable[] = {
    {"reprojection", &QualityThresholds::max_reprojection_px},
    {"view_agreement", &QualityThresholds::max_view_disagreement_mm},
    {"detector_agreement", &QualityThresholds::max_detector_rms_px}};

// The answers as a table: per answer, the tunable checks' values (NaN when the answer
// lacks the check: never flags) and whether a check that is not tuned failed.
struct AnswerTable {
  std::vector<std::vector<double>> values;  // [answer][tunable]
  std::vector<bool> fixed_failed, bad;
  std::vector<bool> present;  // [tunable]: some answer carries the check
};

AnswerTable Tabulate(const std::vector<JudgedAnswer>& answers, double accept_mm) {
  AnswerTable t;
  t.present.assign(std::size(kTunable), false);
  for (const JudgedAnswer& a : answers) {
    std::vector<double> row(std::size(kTunable), std::nan(""));
    bool failed = false;
    for (const QualityFlag& f : a.quality.flags) {
      bool tunable = false;
      for (size_t c = 0; c < std::size(kTunable); ++c) {
        if (f.name != kTunable[c].check) continue;
        row[c] = std::isnan(f.value) ? HUGE_VAL : f.value;
        t.present[c] = tunable = true;
      }
      if (!tunable) failed = failed || !f.passed;
    }
    t.values.push_back(row);
    t.fixed_failed.push_back(failed);
    t.bad.push_back(!(a.error_mm <= accept_mm));
  }
  return t;
}

struct Outcome {
  double youden = 0;
  int kept = 0, kept_bad = 0;
};

Outcome Judge(const AnswerTable& t, const std::vector<double>& thresholds) {
  int tp = 0, fp = 0, bad = 0, good = 0;
  Outcome o;
  for (size_t i = 0; i < t.values.size(); ++i) {
    bool flagged = t.fixed_failed[i];
    for (size_t c = 0; c < thresholds.size(); ++c) {
      const double v = t.values[i][c];
      flagged = flagged || (!std::isnan(v) && !(v <= thresholds[c]));
    }
    bad += t.bad[i];
    good += !t.bad[i];
    tp += flagged && t.bad[i];
    fp += flagged && !t.bad[i];
    o.kept += !flagged;
    o.kept_bad += !flagged && t.bad[i];
  }
  o.youden = double(tp) / std::max(bad, 1) - double(fp) / std::max(good, 1);
  return o;
}

// Per tunable check, the thresholds worth trying: today's and every finite value.
std::vector<std::vector<double>> Candidates(const AnswerTable& t,
                                            const std::vector<double>& current) {
  std::vector<std::vector<double>> candidates(current.size());
  for (size_t c = 0; c < current.size(); ++c) {
    std::set<double> values = {current[c]};
    for (const auto& row : t.values) {
      if (std::isfinite(row[c])) values.insert(row[c]);
    }
    candidates[c].assign(values.begin(), values.end());
  }
  return candidates;
}

// Every combination of candidates (a few thousand for 16 answers); the best by J,
// then by answers kept, strictly better than `best` to replace it.
void Search(const AnswerTable& t, const std::vector<std::vector<double>>& candidates,
            std::vector<double>* chosen, Outcome* best) {
  std::vector<size_t> index(candidates.size(), 0);
  std::vector<double> thresholds(candidates.size());
  while (true) {
    for (size_t c = 0; c < candidates.size(); ++c) thresholds[c] = candidates[c][index[c]];
    const Outcome o = Judge(t, thresholds);
    if (o.youden > best->youden + 1e-12 ||
        (std::abs(o.youden - best->youden) <= 1e-12 && o.kept > best->kept)) {
      *best = o;
      *chosen = thresholds;
    }
    size_t c = 0;
    while (c < candidates.size() && ++index[c] == candidates[c].size()) index[c++] = 0;
    if (c == candidates.size()) return;
  }
}

}  // namespace

QualityThresholds ChooseThresholds(const std::vector<JudgedAnswer>& answers,
                                   const QualityThresholds& current, double accept_mm,
                                   ThresholdStudy* study) {
  const AnswerTable table = Tabulate(answers, accept_mm);
  std::vector<double> now;
  for (const Tunable& k : kTunable) now.push_back(current.*k.threshold);
  ThresholdStudy s;
  s.accept_mm = accept_mm;
  for (bool b : table.bad) (b ? s.bad : s.good) += 1;
  const Outcome today = Judge(table, now);
  Outcome best = today;
  std::vector<double> chosen = now;
  if (s.good > 0 && s.bad > 0) Search(table, Candidates(table, now), &chosen, &best);
  QualityThresholds result = current;
  for (size_t c = 0; c < std::size(kTunable); ++c) {
    result.*kTunable[c].threshold = chosen[c];
    if (table.present[c]) s.checks.push_back({kTunable[c].check, now[c], chosen[c]});
  }
  s.youden_current = today.youden;
  s.youden_chosen = best.youden;
  s.kept_current = today.kept;
  s.kept_chosen = best.kept;
  s.kept_bad_current = today.kept_bad;
  s.kept_bad_chosen = best.kept_bad;
  if (study) *study = s;
  return result;
}

nlohmann::json ThresholdStudy::ToJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const ThresholdChoice& c : checks) {
    list.push_back({{"check", c.check}, {"current", c.current}, {"chosen", c.chosen}});
  }
  return {{"rule",
           "the thresholds whose joint decision (an answer is kept when every check "
           "passes) best flags answers farther than accept_mm from their fit label, "
           "by Youden's J, ties to the one keeping more; the current ones unless "
           "something does strictly better"},
          {"accept_mm", accept_mm},
          {"good_answers", good},
          {"bad_answers", bad},
          {"checks", list},
          {"youden_current", youden_current},
          {"youden_chosen", youden_chosen},
          {"kept_current", kept_current},
          {"kept_chosen", kept_chosen},
          {"kept_bad_current", kept_bad_current},
          {"kept_bad_chosen", kept_bad_chosen}};
}

}  // namespace handlabel
