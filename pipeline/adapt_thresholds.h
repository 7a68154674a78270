#pragma once
// The quality checks' thresholds for an adapted network, chosen on its answers to
// held-out frames (pipeline/adapt.h). An answer is bad when it lies farther than
// accept_mm from its reference label (the fit's). Flagging an answer (some check
// fails) is a detector of bad answers; the three checks that are a matter of degree
// (reprojection, view_agreement, detector_agreement) get the thresholds whose joint
// decision has the best Youden's J (true-positive rate - false-positive rate), ties
// going to the thresholds that keep more answers. Jointly, because the label keeps an
// answer only when every check passes: thresholds chosen check by check each flag
// their own good answers, and together they flag many (on the development recording
// 10 of 13 good answers, where the joint choice flags 2). The current thresholds stay
// when the answers are all good or all bad, or nothing does strictly better.
// finite, range and enough_views are not tuned; an answer failing one stays flagged.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/job_config.h"
#include "pipeline/quality_checks.h"

namespace handlabel {

struct JudgedAnswer {
  double error_mm = 0;    // distance to the reference label (mean keypoint distance)
  QualityReport quality;  // the answer's checks (a job with refine off records them)
};

struct ThresholdChoice {
  std::string check;  // reprojection | view_agreement | detector_agreement
  double current = 0, chosen = 0;
};

struct ThresholdStudy {
  double accept_mm = 0;
  int good = 0, bad = 0;  // answers within / beyond accept_mm
  std::vector<ThresholdChoice> checks;  // the tunable checks the answers carry
  double youden_current = 0, youden_chosen = 0;
  int kept_current = 0, kept_chosen = 0;            // answers passing every check
  int kept_bad_current = 0, kept_bad_chosen = 0;    // ... of them bad
  nlohmann::json ToJson() const;
};

// The thresholds of `current` with the tunable ones replaced by those chosen.
QualityThresholds ChooseThresholds(const std::vector<JudgedAnswer>& answers,
                                   const QualityThresholds& current, double accept_mm,
                                   ThresholdStudy* study = nullptr);

}  // namespace handlabel
