#include "hand/metrics.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

void CheckSameShape(const Points3d& a, const Points3d& b) {
  HL_CHECK(a.rows() == b.rows() && a.rows() > 0,
           "point sets of " + std::to_string(a.rows()) + " and " +
               std::to_string(b.rows()) + " points");
}

}  // namespace

Eigen::VectorXd PointErrors(const Points3d& predicted, const Points3d& truth) {
  CheckSameShape(predicted, truth);
  return (predicted - truth).rowwise().norm();
}

double MeanPointError(const Points3d& predicted, const Points3d& truth) {
  return PointErrors(predicted, truth).mean();
}

double RootRelativeMeanPointError(const Points3d& predicted, const Points3d& truth,
                                  const Eigen::Vector3d& predicted_root,
                                  const Eigen::Vector3d& truth_root) {
  CheckSameShape(predicted, truth);
  const Points3d p = predicted.rowwise() - predicted_root.transpose();
  const Points3d t = truth.rowwise() - truth_root.transpose();
  return MeanPointError(p, t);
}

Points3d SimilarityTransform::Apply(const Points3d& points) const {
  Points3d out =
      (scale * points * rotation.transpose()).rowwise() + translation.transpose();
  return out;
}

SimilarityTransform ProcrustesAlignment(const Points3d& predicted, const Points3d& truth,
                                        bool allow_reflection) {
  CheckSameShape(predicted, truth);
  const Eigen::RowVector3d mean_p = predicted.colwise().mean();
  const Eigen::RowVector3d mean_t = truth.colwise().mean();
  const Eigen::MatrixXd p = predicted.rowwise() - mean_p;
  const Eigen::MatrixXd t = truth.rowwise() - mean_t;
  // Maximise trace(R^T t^T p) over orthogonal R: R = U V^T from svd(t^T p); the optimal
  // scale is sum(singular values) / |p|^2 (the reflection-free variant flips the
  // smallest singular direction when det(U V^T) < 0).
  const Eigen::Matrix3d cov = t.transpose() * p;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d sign = Eigen::Vector3d::Ones();
  if (!allow_reflection &&
      (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) {
    sign[2] = -1.0;
  }
  SimilarityTransform out;
  out.rotation = svd.matrixU() * sign.asDiagonal() * svd.matrixV().transpose();
  const double norm2 = p.squaredNorm();
  out.scale = norm2 > 0 ? svd.singularValues().dot(sign) / norm2 : 1.0;
  out.translation = mean_t.transpose() - out.scale * out.rotation * mean_p.transpose();
  return out;
}

double ProcrustesMeanPointError(const Points3d& predicted, const Points3d& truth,
                                bool allow_reflection) {
  const SimilarityTransform s = ProcrustesAlignment(predicted, truth, allow_reflection);
  return MeanPointError(s.Apply(predicted), truth);
}

void PckOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "min_threshold", min_threshold, 0);
  if (!(max_threshold > min_threshold)) {
    throw InputError(source, "max_threshold", "> min_threshold",
                     OptionValueText(max_threshold));
  }
  RequireAtLeast(source, "steps", steps, 2);
}

double PckAt(const Eigen::MatrixXd& errors, double threshold) {
  HL_CHECK(errors.size() > 0, "empty error matrix");
  // Per point (column): fraction of frames within the threshold; then mean over points.
  const Eigen::MatrixXd within = (errors.array() <= threshold).cast<double>().matrix();
  return within.colwise().mean().mean();
}

PckCurve ComputePck(const Eigen::MatrixXd& errors, const PckOptions& options) {
  options.Check("PckOptions");
  PckCurve curve;
  const double span = options.max_threshold - options.min_threshold;
  for (int i = 0; i < options.steps; ++i) {
    curve.thresholds.push_back(options.min_threshold + span * i / (options.steps - 1));
    curve.pck.push_back(PckAt(errors, curve.thresholds.back()));
  }
  // The per-point AUC is linear in the per-point curve, so the mean of the per-point
  // AUCs equals the AUC of the mean curve.
  double area = 0.0;
  for (int i = 1; i < options.steps; ++i) {
    area += 0.5 * (curve.pck[i] + curve.pck[i - 1]) *
            (curve.thresholds[i] - curve.thresholds[i - 1]);
  }
  curve.auc = area / span;
  return curve;
}

HandFrameMetrics EvaluateHandFrame(const Points3d& predicted_keypoints,
                                   const Points3d& truth_keypoints,
                                   const Points3d& predicted_vertices,
                                   const Points3d& truth_vertices) {
  HandFrameMetrics m;
  const Eigen::Vector3d pred_root = predicted_keypoints.row(0).transpose();
  const Eigen::Vector3d truth_root = truth_keypoints.row(0).transpose();
  m.mpjpe = MeanPointError(predicted_keypoints, truth_keypoints);
  m.rr_mpjpe = RootRelativeMeanPointError(predicted_keypoints, truth_keypoints, pred_root,
                                          truth_root);
  m.pa_mpjpe = ProcrustesMeanPointError(predicted_keypoints, truth_keypoints);
  if (predicted_vertices.rows() > 0 || truth_vertices.rows() > 0) {
    m.mpvpe = MeanPointError(predicted_vertices, truth_vertices);
    m.rr_mpvpe = RootRelativeMeanPointError(predicted_vertices, truth_vertices, pred_root,
                                            truth_root);
    m.pa_mpvpe = ProcrustesMeanPointError(predicted_vertices, truth_vertices);
  }
  return m;
}

}  // namespace handlabel
