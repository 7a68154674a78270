#include "hand/metrics.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "hand/hand_skeleton.h"

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

namespace {

// a = p_{t-1} - 2 p_t + p_{t+1}, per point.
Points3d SecondDifference(const Points3d& before, const Points3d& now,
                          const Points3d& after) {
  return before - 2.0 * now + after;
}

}  // namespace

MotionMetrics ComputeMotionMetrics(const std::vector<MotionFrame>& frames) {
  MotionMetrics m;
  if (frames.empty()) return m;
  const bool with_truth = frames.front().truth.rows() > 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    HL_CHECK(i == 0 || frames[i].number > frames[i - 1].number,
             "motion frames in increasing number order");
    CheckSameShape(frames[i].predicted, frames.front().predicted);
    HL_CHECK((frames[i].truth.rows() > 0) == with_truth,
             "truth for every motion frame or for none");
    if (with_truth) CheckSameShape(frames[i].predicted, frames[i].truth);
  }
  double error = 0, jitter = 0, truth = 0;
  for (size_t i = 1; i + 1 < frames.size(); ++i) {
    const MotionFrame &a = frames[i - 1], &b = frames[i], &c = frames[i + 1];
    if (b.number - a.number != 1 || c.number - b.number != 1) continue;
    const Points3d predicted = SecondDifference(a.predicted, b.predicted, c.predicted);
    jitter += predicted.rowwise().norm().mean();
    if (with_truth) {
      const Points3d actual = SecondDifference(a.truth, b.truth, c.truth);
      error += (predicted - actual).rowwise().norm().mean();
      truth += actual.rowwise().norm().mean();
    }
    ++m.triples;
  }
  if (m.triples == 0) return m;
  m.acceleration_error = error / m.triples;
  m.jitter = jitter / m.triples;
  m.truth_acceleration = truth / m.triples;
  return m;
}

Eigen::VectorXd BoneLengths(const Points3d& keypoints) {
  HL_CHECK(keypoints.rows() == kNumHandKeypoints, "21 keypoints");
  Eigen::VectorXd lengths(kNumHandKeypoints - 1);
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    lengths[k - 1] = (keypoints.row(k) - keypoints.row(kSnapParents[k])).norm();
  }
  return lengths;
}

double MeanBoneLengthError(const Points3d& predicted, const Points3d& truth) {
  return (BoneLengths(predicted) - BoneLengths(truth)).cwiseAbs().mean();
}

}  // namespace handlabel
