#include "pipeline/adapt_thresholds.h"

#include <gtest/gtest.h>

#include <limits>

namespace handlabel {
namespace {

// An answer with the three tunable checks' values (all other checks passed).
JudgedAnswer Answer(double error_mm, double reprojection_px, double agreement_mm,
                    double detector_px) {
  JudgedAnswer a;
  a.error_mm = error_mm;
  a.quality.flags = {{"finite", true, 0, 0, ""},
                     {"reprojection", false, reprojection_px, 0, ""},
                     {"view_agreement", false, agreement_mm, 0, ""},
                     {"detector_agreement", false, detector_px, 0, ""}};
  return a;
}

const ThresholdChoice& Choice(const std::vector<ThresholdChoice>& choices,
                              const std::string& check) {
  for (const ThresholdChoice& c : choices) {
    if (c.check == check) return c;
  }
  throw std::runtime_error("no choice for " + check);
}

// Values that separate good from bad answers exactly: the chosen threshold keeps
// every good answer and flags every bad one (J = 1), at the largest good value.
TEST(AdaptThresholds, ASeparatingValueIsChosenWithJOfOne) {
  const std::vector<JudgedAnswer> answers = {
      Answer(6, 14, 5, 7), Answer(8, 16, 9, 9), Answer(9, 15, 4, 8),   // good
      Answer(15, 30, 8, 20), Answer(20, 25, 12, 25), Answer(30, 40, 5, 11)};  // bad
  QualityThresholds current;  // 12.3 px, 6.1 mm, 12 px
  std::vector<ThresholdChoice> choices;
  const QualityThresholds chosen = ChooseThresholds(answers, current, 10, &choices);
  ASSERT_EQ(choices.size(), 3u);
  EXPECT_EQ(chosen.max_reprojection_px, 16);  // good up to 16, bad from 25
  EXPECT_DOUBLE_EQ(Choice(choices, "reprojection").youden_chosen, 1.0);
  // Today's 12.3 px flags every answer: J = 1 - 1 = 0.
  EXPECT_DOUBLE_EQ(Choice(choices, "reprojection").youden_current, 0.0);
  EXPECT_EQ(chosen.max_detector_rms_px, 9);  // good up to 9, bad from 11
  EXPECT_EQ(Choice(choices, "detector_agreement").good, 3);
  EXPECT_EQ(Choice(choices, "detector_agreement").bad, 3);
  // view_agreement does not separate (bad answers at 5 and 8 mm lie among the good
  // ones): its best J, recomputed here by brute force over every value and today's.
  double best = -2;
  for (double t : {4.0, 5.0, 8.0, 9.0, 12.0, 6.1}) {
    int tp = 0, fp = 0;
    for (const JudgedAnswer& a : answers) {
      const bool flagged = a.quality.flags[2].value > t, bad = a.error_mm > 10;
      tp += flagged && bad;
      fp += flagged && !bad;
    }
    best = std::max(best, tp / 3.0 - fp / 3.0);
  }
  EXPECT_DOUBLE_EQ(Choice(choices, "view_agreement").youden_chosen, best);
  // The other fields are kept.
  EXPECT_EQ(chosen.min_views, current.min_views);
  EXPECT_EQ(chosen.min_confidence, current.min_confidence);
}

TEST(AdaptThresholds, NothingToSeparateKeepsTheCurrentThresholds) {
  const std::vector<JudgedAnswer> all_good = {Answer(3, 20, 9, 30), Answer(4, 5, 1, 2)};
  std::vector<ThresholdChoice> choices;
  const QualityThresholds chosen = ChooseThresholds(all_good, {}, 10, &choices);
  EXPECT_EQ(chosen.max_reprojection_px, QualityThresholds().max_reprojection_px);
  EXPECT_EQ(chosen.max_detector_rms_px, QualityThresholds().max_detector_rms_px);
  EXPECT_EQ(Choice(choices, "reprojection").good, 2);
  EXPECT_EQ(Choice(choices, "reprojection").bad, 0);
}

// A value that is not finite (a view behind the camera) never becomes a threshold and
// is always flagged.
TEST(AdaptThresholds, NonFiniteValuesAreFlaggedNeverChosen) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<JudgedAnswer> answers = {Answer(5, 10, 3, 5), Answer(40, inf, inf, inf)};
  const QualityThresholds chosen = ChooseThresholds(answers, {}, 10);
  EXPECT_EQ(chosen.max_reprojection_px, 12.3);  // J 1 already: nothing does better
  EXPECT_EQ(chosen.max_detector_rms_px, 12);
}

}  // namespace
}  // namespace handlabel
