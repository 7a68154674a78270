#include "pipeline/quality_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/errors.h"
#include "core/option_checks.h"
#include "geometry/triangulation.h"

namespace handlabel {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string Format(double value) {
  std::ostringstream out;
  out.precision(3);
  out << value;
  return out.str();
}

int CountNonFinite(const MeshPrediction& p) {
  int bad = 0;
  bad += static_cast<int>((!p.vertices.array().isFinite()).count());
  bad += static_cast<int>((!p.keypoints.array().isFinite()).count());
  for (const Keypoints2d& view : p.keypoints_2d) {
    bad += static_cast<int>((!view.uv_px.array().isFinite()).count());
    bad += static_cast<int>((!view.confidence.array().isFinite()).count());
  }
  return bad;
}

double HandSpan(const Points3d& keypoints) {
  double span = 0;
  for (int i = 0; i < keypoints.rows(); ++i) {
    for (int j = i + 1; j < keypoints.rows(); ++j) {
      span = std::max(span, (keypoints.row(i) - keypoints.row(j)).norm());
    }
  }
  return span;
}

// Views whose mean keypoint confidence makes them evidence.
std::vector<bool> ConfidentViews(const MeshPrediction& prediction, int num_views,
                                 const QualityThresholds& t) {
  std::vector<bool> confident(num_views, false);
  for (int v = 0; v < num_views; ++v) {
    confident[v] = prediction.keypoints_2d[v].confidence.mean() >= t.min_confidence;
  }
  return confident;
}

// Hand span within the allowed range and no keypoint behind a confident camera.
QualityFlag RangeFlag(const Rig& rig, const MeshPrediction& prediction,
                      const std::vector<bool>& confident, const QualityThresholds& t) {
  QualityFlag range{"range", false, HandSpan(prediction.keypoints), t.max_hand_span_m,
                    ""};
  int behind = 0;
  for (int v = 0; v < static_cast<int>(confident.size()); ++v) {
    if (!confident[v]) continue;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const Eigen::Vector3d p =
          rig[v].cam_from_world * prediction.keypoints.row(k).transpose();
      behind += p.z() <= 0;
    }
  }
  range.passed =
      range.value >= t.min_hand_span_m && range.value <= t.max_hand_span_m && behind == 0;
  range.detail = "hand span " + Format(range.value) + " m (allowed " +
                 Format(t.min_hand_span_m) + ".." + Format(t.max_hand_span_m) + "), " +
                 std::to_string(behind) + " keypoint(s) behind a camera";
  return range;
}

// The worst confident view's RMS distance between the projected 3D keypoints and its
// own confident 2D keypoints.
QualityFlag ReprojectionFlag(const Rig& rig, const MeshPrediction& prediction,
                             const std::vector<bool>& confident, int confident_views,
                             const QualityThresholds& t) {
  QualityFlag reprojection{"reprojection", false, 0, t.max_reprojection_px, ""};
  int worst_view = -1;
  for (int v = 0; v < static_cast<int>(confident.size()); ++v) {
    if (!confident[v]) continue;
    double sum_sq = 0;
    int count = 0;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (prediction.keypoints_2d[v].confidence(k) < t.min_confidence) continue;
      Eigen::Vector2d uv;
      const bool in_front =
          rig[v].ProjectWorld(prediction.keypoints.row(k).transpose(), &uv);
      const double err =
          in_front ? (uv - prediction.keypoints_2d[v].uv_px.row(k).transpose()).norm()
                   : kInf;
      sum_sq += err * err;
      ++count;
    }
    const double rms = count > 0 ? std::sqrt(sum_sq / count) : 0.0;
    if (rms >= reprojection.value) {
      reprojection.value = rms;
      worst_view = v;
    }
  }
  reprojection.passed =
      confident_views > 0 && reprojection.value <= t.max_reprojection_px;
  reprojection.detail = confident_views == 0
                            ? "no confident view"
                            : "worst view " + rig[worst_view].name + ": RMS " +
                                  Format(reprojection.value) + " px";
  return reprojection;
}

// Mean distance between the 3D keypoints and those triangulated from the confident
// 2D keypoints.
QualityFlag ViewAgreementFlag(const Rig& rig, const MeshPrediction& prediction,
                              const std::vector<bool>& confident,
                              const QualityThresholds& t) {
  QualityFlag agreement{"view_agreement", false, kInf, t.max_view_disagreement_mm, ""};
  double sum_mm = 0;
  int triangulated = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    std::vector<ViewObservation> observations;
    for (int v = 0; v < static_cast<int>(confident.size()); ++v) {
      const double c = prediction.keypoints_2d[v].confidence(k);
      if (!confident[v] || c < t.min_confidence) continue;
      observations.push_back({v, prediction.keypoints_2d[v].uv_px.row(k).transpose(), c});
    }
    const auto point = TriangulateWeighted(rig, observations);
    if (!point) continue;
    sum_mm += 1000.0 * (*point - prediction.keypoints.row(k).transpose()).norm();
    ++triangulated;
  }
  if (triangulated > 0) agreement.value = sum_mm / triangulated;
  agreement.passed = triangulated > 0 && agreement.value <= t.max_view_disagreement_mm;
  agreement.detail = triangulated == 0
                         ? "no keypoint seen confidently in two views"
                         : "mean distance " + Format(agreement.value) + " mm over " +
                               std::to_string(triangulated) + " triangulated keypoints";
  return agreement;
}

// The median over the views with file 2D (a detector's) of the RMS pixel distance
// between the answer's projected keypoints and that view's confident keypoints. The
// median, because one view's detector can lock onto the wrong hand or finger.
QualityFlag DetectorAgreementFlag(const Rig& rig, const MeshPrediction& prediction,
                                  const std::vector<std::optional<Keypoints2d>>& files,
                                  const QualityThresholds& t) {
  std::vector<double> view_rms;
  for (size_t v = 0; v < files.size() && v < rig.size(); ++v) {
    if (!files[v] || !(files[v]->confidence.mean() >= t.min_confidence)) continue;
    double sum_sq = 0;
    int count = 0;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!(files[v]->confidence(k) >= t.min_confidence)) continue;
      Eigen::Vector2d uv;
      const bool in_front =
          rig[v].ProjectWorld(prediction.keypoints.row(k).transpose(), &uv);
      const double err =
          in_front ? (uv - files[v]->uv_px.row(k).transpose()).norm() : kInf;
      sum_sq += err * err;
      ++count;
    }
    if (count > 0) view_rms.push_back(std::sqrt(sum_sq / count));
  }
  QualityFlag flag{"detector_agreement", false, kInf, t.max_detector_rms_px, ""};
  if (view_rms.empty()) {
    flag.detail = "no view with confident file 2D keypoints";
    return flag;
  }
  std::sort(view_rms.begin(), view_rms.end());
  const size_t n = view_rms.size();
  flag.value = n % 2 ? view_rms[n / 2] : 0.5 * (view_rms[n / 2 - 1] + view_rms[n / 2]);
  flag.passed = flag.value <= t.max_detector_rms_px;
  flag.detail = "median over " + std::to_string(n) + " views with file 2D: RMS " +
                Format(flag.value) + " px";
  return flag;
}

}  // namespace

nlohmann::json QualityFlagJson(const QualityFlag& f) {
  return {{"name", f.name},
          {"passed", f.passed},
          {"value", f.value},
          {"threshold", f.threshold},
          {"detail", f.detail}};
}

bool QualityReport::Passed() const {
  for (const QualityFlag& f : flags) {
    if (!f.passed) return false;
  }
  return true;
}

std::string QualityReport::FailedNames() const {
  std::string names;
  for (const QualityFlag& f : flags) {
    if (!f.passed) names += (names.empty() ? "" : ",") + f.name;
  }
  return names;
}

QualityReport CheckPrediction(const Rig& rig, const MeshPrediction& prediction,
                              const QualityThresholds& t,
                              const std::vector<std::optional<Keypoints2d>>* file_2d) {
  QualityReport report;
  const int num_views = static_cast<int>(rig.size());
  const bool shapes_ok = prediction.keypoints.rows() == kNumHandKeypoints &&
                         static_cast<int>(prediction.keypoints_2d.size()) == num_views;

  QualityFlag finite{"finite", false, 0, 0, ""};
  finite.value = CountNonFinite(prediction);
  finite.passed = shapes_ok && finite.value == 0;
  finite.detail = !shapes_ok ? "expected 21 keypoints and one 2D set per view"
                             : Format(finite.value) + " non-finite values";
  if (!finite.passed) {
    report.flags.push_back(finite);
    std::vector<std::string> names = {"range", "enough_views", "reprojection",
                                      "view_agreement"};
    if (file_2d && !file_2d->empty()) names.push_back("detector_agreement");
    for (const std::string& name : names) {
      report.flags.push_back(
          {name, false, kInf, 0, "not checked: prediction not finite"});
    }
    return report;
  }
  report.flags.push_back(finite);

  const std::vector<bool> confident = ConfidentViews(prediction, num_views, t);
  int confident_views = 0;
  for (bool c : confident) confident_views += c;
  report.flags.push_back(RangeFlag(rig, prediction, confident, t));
  report.flags.push_back(
      {"enough_views", confident_views >= t.min_views, double(confident_views),
       double(t.min_views),
       std::to_string(confident_views) + " of " + std::to_string(num_views) +
           " views with mean confidence >= " + Format(t.min_confidence)});
  report.flags.push_back(
      ReprojectionFlag(rig, prediction, confident, confident_views, t));
  report.flags.push_back(ViewAgreementFlag(rig, prediction, confident, t));
  if (file_2d && !file_2d->empty()) {
    report.flags.push_back(DetectorAgreementFlag(rig, prediction, *file_2d, t));
  }
  return report;
}

void SilhouetteCheckThresholds::Check(const std::string& source) const {
  RequireAtLeast(source, "max_keypoint_rms_rise_px", max_keypoint_rms_rise_px, 0);
  RequireInRange(source, "min_view_iou", min_view_iou, 0, 1);
}

QualityReport CheckSilhouetteFit(const HandFitStageResult& silhouette_fit,
                                 const HandFitStageResult& keypoints_only,
                                 const SilhouetteCheckThresholds& t) {
  HL_CHECK(silhouette_fit.view_rms_px.size() == keypoints_only.view_rms_px.size() &&
               silhouette_fit.view_iou.size() == silhouette_fit.view_rms_px.size(),
           "the two fits have the same views");
  QualityReport report;
  double rise = 0;
  int views = 0;
  for (size_t v = 0; v < silhouette_fit.view_rms_px.size(); ++v) {
    const double a = silhouette_fit.view_rms_px[v], b = keypoints_only.view_rms_px[v];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    rise += a - b;
    ++views;
  }
  if (views > 0) rise /= views;
  report.flags.push_back({"keypoint_agreement", rise <= t.max_keypoint_rms_rise_px, rise,
                          t.max_keypoint_rms_rise_px,
                          "keypoint RMS " + Format(rise) +
                              " px above the keypoints-only fit's (mean over " +
                              std::to_string(views) + " views)"});
  double worst = kInf;
  int worst_view = -1;
  for (size_t v = 0; v < silhouette_fit.view_iou.size(); ++v) {
    if (std::isfinite(silhouette_fit.view_iou[v]) && silhouette_fit.view_iou[v] < worst) {
      worst = silhouette_fit.view_iou[v];
      worst_view = static_cast<int>(v);
    }
  }
  const bool any = worst_view >= 0;
  report.flags.push_back(
      {"silhouette_iou", !any || worst >= t.min_view_iou, any ? worst : 1.0,
       t.min_view_iou,
       any ? "worst IoU " + Format(worst) + " in view " + std::to_string(worst_view)
           : "no view with a mask"});
  return report;
}

}  // namespace handlabel
