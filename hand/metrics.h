#pragma once
// Accuracy metrics of 3D hand predictions, with the definitions of the POEM paper's
// evaluation code (lib/metrics of POEM, CVPR 2023), so our numbers compare with its
// tables:
//   MPJPE / MPVPE   mean Euclidean distance over points (21 keypoints / all vertices)
//                   of one frame; a data set's value is the mean over frames.
//   root-relative   both point sets minus their own root point (the wrist keypoint,
//                   SNAP index 0) before the distance.
//   PA-             after aligning the prediction to the ground truth with a similarity
//                   transform (scale, orthogonal matrix, translation) that minimises
//                   the squared distance: POEM's align_w_scale, i.e. SciPy's
//                   orthogonal_procrustes on centred, norm-scaled sets. Like POEM it
//                   allows a reflection unless asked not to.
//   PCK / AUC       per point: fraction of frames whose error is <= threshold; the
//                   curve at `steps` thresholds linspace(min, max) (POEM configs: 0 to
//                   20 mm, 20 steps), AUC = trapezoid area / (max - min), both averaged
//                   over the points.
// All distances are in the units of the inputs (metres in this project).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "hand/hand_lbs.h"

namespace handlabel {

// Distance of each point pair; sets must have the same size.
Eigen::VectorXd PointErrors(const Points3d& predicted, const Points3d& truth);
// Mean of PointErrors: MPJPE for keypoints, MPVPE for vertices.
double MeanPointError(const Points3d& predicted, const Points3d& truth);
// Mean error after subtracting each set's own root point (row `root` of each
// keypoint set) from the points.
double RootRelativeMeanPointError(const Points3d& predicted, const Points3d& truth,
                                  const Eigen::Vector3d& predicted_root,
                                  const Eigen::Vector3d& truth_root);

// aligned = scale * rotation * p + translation.
struct SimilarityTransform {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // orthogonal
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Points3d Apply(const Points3d& points) const;
};

// The least-squares similarity taking `predicted` onto `truth` (POEM's align_w_scale).
// allow_reflection = false restricts the matrix to a rotation (Umeyama).
SimilarityTransform ProcrustesAlignment(const Points3d& predicted, const Points3d& truth,
                                        bool allow_reflection = true);
// Mean error after ProcrustesAlignment: PA-MPJPE / PA-MPVPE.
double ProcrustesMeanPointError(const Points3d& predicted, const Points3d& truth,
                                bool allow_reflection = true);

struct PckOptions {
  double min_threshold = 0.0;   // metres; first threshold of the curve
  double max_threshold = 0.02;  // metres; last threshold (POEM: 20 mm)
  int steps = 20;               // number of thresholds, linspace(min, max, steps)
  // Throws InputError unless 0 <= min < max and steps >= 2.
  void Check(const std::string& source) const;
};

struct PckCurve {
  std::vector<double> thresholds;
  std::vector<double> pck;  // mean over points of the per-point PCK at each threshold
  double auc = 0.0;         // mean over points of the normalised per-point AUC
};

// errors: frames x points (e.g. PointErrors of every frame as rows).
PckCurve ComputePck(const Eigen::MatrixXd& errors, const PckOptions& options = {});
// PCK at one threshold, averaged over points.
double PckAt(const Eigen::MatrixXd& errors, double threshold);

// Every metric of one frame (metres). Root = keypoint 0 (wrist) of each set.
struct HandFrameMetrics {
  double mpjpe = 0.0;
  double mpvpe = 0.0;
  double rr_mpjpe = 0.0;  // root-relative
  double rr_mpvpe = 0.0;
  double pa_mpjpe = 0.0;  // Procrustes-aligned with scale
  double pa_mpvpe = 0.0;
};
// Vertices may be empty on both sides (vertex metrics are then 0).
HandFrameMetrics EvaluateHandFrame(const Points3d& predicted_keypoints,
                                   const Points3d& truth_keypoints,
                                   const Points3d& predicted_vertices,
                                   const Points3d& truth_vertices);

// Motion over time, as video methods report it (VIBE, Kocabas et al. 2020: "acceleration
// error"): the acceleration of a point at frame t is the second finite difference
// a_t = p_{t-1} - 2 p_t + p_{t+1}, in units per frame^2 (so it depends on the frame
// rate). Over every triple of consecutive frames and every point:
//   acceleration error   mean |a_predicted - a_truth|
//   jitter               mean |a_predicted|
//   truth acceleration   mean |a_truth| (what the true motion itself accelerates)
// Frames carry numbers; only triples numbered n - 1, n, n + 1 count, so a missing or
// failed frame is never differenced across.
struct MotionFrame {
  int64_t number = 0;  // consecutive frames have consecutive numbers
  Points3d predicted;
  Points3d truth;  // same size as predicted, or empty (jitter only)
};

struct MotionMetrics {
  int triples = 0;                  // triples of consecutive frames
  double acceleration_error = 0.0;  // 0 without truth or triples
  double jitter = 0.0;
  double truth_acceleration = 0.0;
};

// `frames` in increasing number order, every one with truth or none of them.
MotionMetrics ComputeMotionMetrics(const std::vector<MotionFrame>& frames);

// Lengths of the 20 bones of the 21-keypoint skeleton (SNAP order): entry k - 1 is the
// distance from keypoint k to its parent kSnapParents[k] (hand/hand_skeleton.h).
Eigen::VectorXd BoneLengths(const Points3d& keypoints);
// Mean over the 20 bones of |length - the truth's length|: how far a hand's proportions
// are from the truth's, whatever its pose and place (same units as the inputs).
double MeanBoneLengthError(const Points3d& predicted, const Points3d& truth);

}  // namespace handlabel
