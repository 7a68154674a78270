#pragma once
// The quality checks' thresholds for an adapted network, chosen on its answers to
// held-out frames (pipeline/adapt.h): for each check that is a matter of degree
// (reprojection, view_agreement, detector_agreement), flagging "value > threshold" is
// a detector of bad answers (error to the reference label > accept_mm); the threshold
// with the best Youden's J (true-positive rate - false-positive rate) over the
// answers' own values is chosen, as issue 20 chose the shipped network's on synthetic
// answers (docs/comparison.md). The current threshold stays when the answers are all
// good or all bad (nothing to separate) or no value does strictly better.

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
  double youden_current = 0, youden_chosen = 0;
  int good = 0, bad = 0;  // answers with and without the check's value
};

// The thresholds of `current` with the tunable ones replaced by those chosen;
// `choices` (if not null) gets one entry per tunable check the answers carry.
QualityThresholds ChooseThresholds(const std::vector<JudgedAnswer>& answers,
                                   const QualityThresholds& current, double accept_mm,
                                   std::vector<ThresholdChoice>* choices = nullptr);

nlohmann::json ThresholdChoicesJson(const std::vector<ThresholdChoice>& choices,
                                    double accept_mm);

}  // namespace handlabel
