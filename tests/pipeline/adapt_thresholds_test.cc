#include "pipeline/adapt_thresholds.h"

#include <gtest/gtest.h>

#include <limits>

namespace handlabel {
namespace {

// An answer with the three tunable checks' values and a check that is not tuned.
JudgedAnswer Answer(double error_mm, double reprojection_px, double agreement_mm,
                    double detector_px, bool in_range = true) {
  JudgedAnswer a;
  a.error_mm = error_mm;
  a.quality.flags = {{"range", in_range, 0, 0, ""},
                     {"reprojection", false, reprojection_px, 0, ""},
                     {"view_agreement", false, agreement_mm, 0, ""},
                     {"detector_agreement", false, detector_px, 0, ""}};
  return a;
}

// Youden's J of "kept iff every check passes under t" as a detector of bad answers,
// written out directly.
double JointYouden(const std::vector<JudgedAnswer>& answers, const QualityThresholds& t,
                   double accept_mm, int* kept) {
  int tp = 0, fp = 0, bad = 0, good = 0;
  *kept = 0;
  for (const JudgedAnswer& a : answers) {
    const bool flagged = !a.quality.flags[0].passed ||
                         a.quality.flags[1].value > t.max_reprojection_px ||
                         a.quality.flags[2].value > t.max_view_disagreement_mm ||
                         a.quality.flags[3].value > t.max_detector_rms_px;
    const bool is_bad = a.error_mm > accept_mm;
    bad += is_bad;
    good += !is_bad;
    tp += flagged && is_bad;
    fp += flagged && !is_bad;
    *kept += !flagged;
  }
  return double(tp) / bad - double(fp) / good;
}

// One check separates good from bad answers; the others would flag good ones too.
// The joint choice keeps every good answer: the separating threshold, the others
// loose enough to flag nothing (the check-by-check choice would have flagged some).
TEST(AdaptThresholds, TheJointChoiceKeepsEveryGoodAnswerWhenOneCheckSeparates) {
  const std::vector<JudgedAnswer> answers = {
      Answer(6, 14, 3, 11), Answer(8, 30, 4, 7), Answer(9, 15, 2, 20),  // good
      Answer(15, 16, 8, 9), Answer(20, 25, 9, 12), Answer(30, 12, 12, 8)};  // bad
  ThresholdStudy study;
  const QualityThresholds chosen = ChooseThresholds(answers, {}, 10, &study);
  EXPECT_EQ(chosen.max_view_disagreement_mm, 4);  // good up to 4 mm, bad from 8
  EXPECT_GE(chosen.max_reprojection_px, 30);      // flags no good answer
  EXPECT_GE(chosen.max_detector_rms_px, 20);
  EXPECT_DOUBLE_EQ(study.youden_chosen, 1.0);
  EXPECT_EQ(study.kept_chosen, 3);
  EXPECT_EQ(study.kept_bad_chosen, 0);
  EXPECT_EQ(study.good, 3);
  EXPECT_EQ(study.bad, 3);
  int kept = 0;
  EXPECT_DOUBLE_EQ(study.youden_current, JointYouden(answers, {}, 10, &kept));
  EXPECT_EQ(study.kept_current, kept);
  // The other fields are kept.
  EXPECT_EQ(chosen.min_views, QualityThresholds().min_views);
}

// Overlapping values: the choice is the best of every combination, checked here
// against a brute-force search over a grid that holds every value.
TEST(AdaptThresholds, TheChoiceIsTheBestCombination) {
  std::vector<JudgedAnswer> answers;
  for (int i = 0; i < 12; ++i) {
    const double e = 3 + 1.5 * i;  // 3 .. 19.5 mm, bad from 10.5
    answers.push_back(Answer(e, 5 + (i * 7) % 11 + 0.5 * i, 1 + (i * 5) % 7 + 0.3 * i,
                             4 + (i * 3) % 5 + 0.6 * i));
  }
  answers[2].quality.flags[0].passed = false;  // a good answer out of range: flagged
  ThresholdStudy study;
  const QualityThresholds chosen = ChooseThresholds(answers, {}, 10, &study);
  int kept = 0;
  const double j = JointYouden(answers, chosen, 10, &kept);
  EXPECT_DOUBLE_EQ(j, study.youden_chosen);
  EXPECT_EQ(kept, study.kept_chosen);
  for (const JudgedAnswer& a : answers) {
    for (const JudgedAnswer& b : answers) {
      for (const JudgedAnswer& c : answers) {
        QualityThresholds t;
        t.max_reprojection_px = a.quality.flags[1].value;
        t.max_view_disagreement_mm = b.quality.flags[2].value;
        t.max_detector_rms_px = c.quality.flags[3].value;
        int k = 0;
        EXPECT_LE(JointYouden(answers, t, 10, &k), j + 1e-12);
      }
    }
  }
}

TEST(AdaptThresholds, NothingToSeparateKeepsTheCurrentThresholds) {
  const std::vector<JudgedAnswer> all_good = {Answer(3, 20, 9, 30), Answer(4, 5, 1, 2)};
  ThresholdStudy study;
  const QualityThresholds chosen = ChooseThresholds(all_good, {}, 10, &study);
  EXPECT_EQ(chosen.max_reprojection_px, QualityThresholds().max_reprojection_px);
  EXPECT_EQ(chosen.max_detector_rms_px, QualityThresholds().max_detector_rms_px);
  EXPECT_EQ(study.good, 2);
  EXPECT_EQ(study.bad, 0);
  EXPECT_EQ(study.checks.size(), 3u);
}

// A value that is not finite (a view behind the camera) never becomes a threshold and
// is always flagged; thresholds already perfect stay.
TEST(AdaptThresholds, NonFiniteValuesAreFlaggedNeverChosen) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<JudgedAnswer> answers = {Answer(5, 10, 3, 5), Answer(40, inf, inf, inf)};
  const QualityThresholds chosen = ChooseThresholds(answers, {}, 10);
  EXPECT_EQ(chosen.max_reprojection_px, 12.3);
  EXPECT_EQ(chosen.max_view_disagreement_mm, 6.1);
  EXPECT_EQ(chosen.max_detector_rms_px, 12);
}

}  // namespace
}  // namespace handlabel
