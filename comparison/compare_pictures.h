#pragma once
// The pictures of `handlabel compare`'s report (compare_report.h), each an RGB image;
// an empty image when there is nothing to draw (no scored method, no ablation, no QA).

#include <string>
#include <vector>

#include "image/image.h"
#include "comparison/compare_qa.h"
#include "comparison/compare_run.h"

namespace handlabel {

inline bool MethodRan(const MethodRun& run) { return run.why_not.empty(); }
inline bool MethodHasVertices(const MethodRun& run) {
  return run.scores.vertex_errors.cols() > 0;
}

// The methods that ran and have ground truth: the ones pictures and tables score.
std::vector<const MethodRun*> ScoredMethods(const CompareResult& r);

// Metres to millimetres, element-wise.
std::vector<double> Millimetres(std::vector<double> metres);

// `value` with `decimals` decimals; "-" when it is not finite.
std::string FormatFixed(double value, int decimals);

ImageU8 PckPicture(const CompareResult& r);           // 3D PCK curves of every method
ImageU8 PerJointPicture(const CompareResult& r);      // mean error per keypoint
ImageU8 HistogramPicture(const CompareResult& r);     // per-frame MPJPE histogram
ImageU8 TimeAccuracyPicture(const CompareResult& r);  // seconds per frame vs MPJPE
ImageU8 AblationPicture(const CompareResult& r);      // MPJPE against the view count
ImageU8 QaScatterPicture(const QualityStudy& qa);     // check value vs the answer's error
ImageU8 QaRocPicture(const QualityStudy& qa);         // ROC of each check

// One row per frame of the `count` worst (by the first scored method's MPJPE): the
// truth, then every scored method's label, drawn on the view where the hand is largest.
ImageU8 WorstFramesPicture(const JobConfig& base, const CompareResult& r, int count);

}  // namespace handlabel
