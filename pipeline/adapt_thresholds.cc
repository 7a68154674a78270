#include "pipeline/adapt_thresholds.h"

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

// Youden's J of flagging value > threshold as bad.
double Youden(const std::vector<double>& values, const std::vector<bool>& bad,
              double threshold) {
  int tp = 0, fp = 0, positives = 0, negatives = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    const bool flagged = !(values[i] <= threshold);  // NaN and infinity are flagged
    positives += bad[i];
    negatives += !bad[i];
    tp += flagged && bad[i];
    fp += flagged && !bad[i];
  }
  return double(tp) / positives - double(fp) / negatives;
}

// The check's values and the answers' classes, for the answers that carry it.
void Collect(const std::vector<JudgedAnswer>& answers, const std::string& check,
             double accept_mm, std::vector<double>* values, std::vector<bool>* bad) {
  for (const JudgedAnswer& a : answers) {
    for (const QualityFlag& f : a.quality.flags) {
      if (f.name != check) continue;
      values->push_back(f.value);
      bad->push_back(!(a.error_mm <= accept_mm));
    }
  }
}

}  // namespace

QualityThresholds ChooseThresholds(const std::vector<JudgedAnswer>& answers,
                                   const QualityThresholds& current, double accept_mm,
                                   std::vector<ThresholdChoice>* choices) {
  QualityThresholds chosen = current;
  for (const Tunable& t : kTunable) {
    std::vector<double> values;
    std::vector<bool> bad;
    Collect(answers, t.check, accept_mm, &values, &bad);
    if (values.empty()) continue;
    ThresholdChoice c{t.check, current.*t.threshold, current.*t.threshold, 0, 0, 0, 0};
    for (bool b : bad) (b ? c.bad : c.good) += 1;
    if (c.good > 0 && c.bad > 0) {
      c.youden_current = c.youden_chosen = Youden(values, bad, c.current);
      // Candidates: every finite value (a threshold at a value keeps that answer).
      const std::set<double> candidates(values.begin(), values.end());
      for (double v : candidates) {
        if (!std::isfinite(v)) continue;
        const double j = Youden(values, bad, v);
        if (j > c.youden_chosen) {
          c.youden_chosen = j;
          c.chosen = v;
        }
      }
      chosen.*t.threshold = c.chosen;
    }
    if (choices) choices->push_back(c);
  }
  return chosen;
}

nlohmann::json ThresholdChoicesJson(const std::vector<ThresholdChoice>& choices,
                                    double accept_mm) {
  nlohmann::json checks = nlohmann::json::array();
  for (const ThresholdChoice& c : choices) {
    checks.push_back({{"check", c.check},
                      {"current", c.current},
                      {"chosen", c.chosen},
                      {"youden_current", c.youden_current},
                      {"youden_chosen", c.youden_chosen},
                      {"good_answers", c.good},
                      {"bad_answers", c.bad}});
  }
  return {{"rule",
           "per check, the threshold with the best Youden's J for flagging answers "
           "farther than accept_mm from their fit label; the current one unless one "
           "does strictly better"},
          {"accept_mm", accept_mm},
          {"checks", checks}};
}

}  // namespace handlabel
