#pragma once
// The quality checks of the fallback policy (pipeline/quality_checks.h) measured
// against the truth: for every network answer of a comparison (the `network` method,
// refine off, so every label carries all five checks with their values), each check's
// value against the answer's MPJPE. A "bad" answer has MPJPE > error_mm.
//  - ROC per tunable check (reprojection, view_agreement): flagging "value >
//    threshold" as a detector of bad answers, over every threshold.
//  - Precision / recall of the current threshold.
//  - Thresholds chosen on a selection set by Youden's J (true-positive rate -
//    false-positive rate; the current threshold stays unless one does strictly
//    better), and judged on held-out answers: the share of kept answers (every check
//    passes) that are bad, before (current thresholds) and after. The selection set is
//    either this run's frames at even positions in frame order (held out: the odd
//    ones), or the network answers of earlier comparisons (`compare --qa-selection
//    DIR,...`; held out: every answer of this run, frames never used for choosing).
// finite, range and enough_views are kept as they are (what they test is not a matter
// of degree); their recorded pass/fail enters "kept" unchanged.

#include <string>
#include <vector>

#include "comparison/compare_run.h"
#include "pipeline/job_config.h"

namespace handlabel {

struct RocPoint {
  double threshold = 0;
  double false_positive_rate = 0, true_positive_rate = 0;
};

struct CheckStudy {
  std::string name;                // reprojection | view_agreement
  std::string unit;                // px | mm
  std::vector<double> values;      // per frame (all frames), in `unit`
  std::vector<double> errors_mm;   // the answer's MPJPE per frame
  std::vector<RocPoint> roc;       // all frames, thresholds ascending
  double roc_auc = 0;              // area under the ROC curve; NaN: one class empty
  double current = 0, chosen = 0;  // thresholds, in `unit`
  RocPoint at_current, at_chosen;  // the ROC at those thresholds (all frames)
  // On the held-out frames: precision and recall of "flagged" for "bad".
  double precision_current = 0, recall_current = 0;
  double precision_chosen = 0, recall_chosen = 0;
};

struct KeptShare {
  int answers = 0;   // held-out answers
  int kept = 0;      // of those, passing every check
  int kept_bad = 0;  // of the kept, MPJPE > error_mm
  double Share() const { return kept > 0 ? double(kept_bad) / kept : 0.0; }
  double KeptFraction() const { return answers > 0 ? double(kept) / answers : 0.0; }
};

struct QualityStudy {
  std::string why_not;  // non-empty: no study (no network, no truth), and why
  double error_mm = 8;
  // The compare folders whose network answers were the selection set; empty: the
  // even positions of this run.
  std::vector<std::string> selection_dirs;
  int frames = 0, selection_frames = 0, held_out_frames = 0;
  int bad_frames = 0;  // over this run's frames
  std::vector<CheckStudy> checks;
  QualityThresholds current, chosen;
  KeptShare before, after;  // held-out frames
};

// `network`: the comparison's network run (refine off). `current`: the thresholds
// its labels were checked with. `selection_dirs`: earlier `compare` output folders
// (their compare.json and methods/network/labels) to choose on; throws InputError
// naming the folder when one has no network row.
QualityStudy StudyQualityChecks(const MethodRun& network,
                                const QualityThresholds& current, double error_mm,
                                const std::vector<std::string>& selection_dirs = {});

}  // namespace handlabel
