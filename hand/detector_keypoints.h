#pragma once
// Where a 2D hand detector puts its 21 keypoints on the hand model (issue 45). A
// detector trained on photos (MediaPipe) marks its own points: its "MCP"s and "wrist"
// lie on the skin, its finger joints at other places along the bones than the model's
// joints. Fitting the model's joints to them stretches or shortens bones the same way
// in every frame, which no averaging over frames removes. This model says where the
// detector's keypoint k lies on a posed hand:
//   D_k = K_k + sum_i w_ki (V_{v_ki} - K_k)
// with K_k the model's own keypoint (SNAP order, HandEvaluator's) and V the posed mesh
// vertices near it: an affine combination, so D_k moves, turns and scales with the skin
// around the joint (like MANO's joint regressor), and the same vertex weights serve
// both hands of one topology (mirroring maps the combination onto itself). All weights
// zero: the detector marks the model's keypoints.
//
// Learned from synthetic renders with exact truth (LearnDetectorKeypoints: detections
// triangulated, against the truth's posed mesh; the command `handlabel model
// detector-keypoints`, docs/fitting.md "Where the detector's keypoints are"). The fit
// uses it in its 2D keypoint term only, so that the fitted hand's own joints and bones
// stay the model's.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "hand/hand_evaluator.h"
#include "hand/hand_lbs.h"

namespace handlabel {

struct DetectorKeypointModel {
  std::string detector;  // whose keypoints, e.g. "mediapipe"
  std::string learned;   // how it was made (command, captures, seeds): provenance
  int num_vertices = 0;  // of the hand model topology the vertex ids index
  // Per keypoint (SNAP order): mesh vertex ids and their weights, the same length.
  std::array<std::vector<int>, kNumHandKeypoints> vertices;
  std::array<std::vector<double>, kNumHandKeypoints> weights;

  // Every keypoint's vertex ids, concatenated in keypoint order (the layout the
  // evaluation functions below read vertices in).
  std::vector<int> AllVertexIds() const;
  // Throws InputError naming `source` when the sizes do not fit each other or a model
  // with `model_vertices` vertices.
  void Check(const std::string& source, int model_vertices) const;
};

// The detector's keypoints from the model's keypoints (63 values, SNAP order) and the
// posed vertices AllVertexIds() (3 per id), `columns` values per coordinate: 1 for
// points, num_params for Jacobian rows (the map is linear).
template <typename T>
void ApplyDetectorKeypoints(const DetectorKeypointModel& model, const T* keypoints,
                            const T* vertices, int columns, T* out) {
  int next = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    double own = 1.0;
    for (double w : model.weights[k]) own -= w;
    for (int c = 0; c < 3; ++c) {
      const T* from = keypoints + (3 * k + c) * columns;
      T* to = out + (3 * k + c) * columns;
      for (int j = 0; j < columns; ++j) to[j] = from[j] * own;
      for (size_t i = 0; i < model.weights[k].size(); ++i) {
        const T* v = vertices + (3 * (next + i) + c) * columns;
        for (int j = 0; j < columns; ++j) to[j] += v[j] * model.weights[k][i];
      }
    }
    next += static_cast<int>(model.weights[k].size());
  }
}

// The detector's 21 keypoints of the hand with these parameters (as HandEvaluator
// reads them), templated for autodiff; `vertex_ids` = model.AllVertexIds().
template <typename T>
void DetectorKeypoints(const HandEvaluator& evaluator, const DetectorKeypointModel& model,
                       const std::vector<int>& vertex_ids, const T* global_orient,
                       const T* hand_pose, const T* betas, const T* transl, T* out63) {
  HandPoseState<T> state;
  evaluator.Pose(global_orient, hand_pose, betas, transl, &state);
  T keypoints[3 * kNumHandKeypoints];
  evaluator.KeypointsFromState(state, keypoints);
  std::vector<T> vertices(3 * vertex_ids.size());
  evaluator.VerticesFromState(state, vertex_ids, vertices.data());
  ApplyDetectorKeypoints(model, keypoints, vertices.data(), 1, out63);
}

// The same in doubles with the Jacobian, row-major 63 x evaluator.num_params() as
// HandEvaluator::KeypointsAndJacobian.
void DetectorKeypointsAndJacobian(const HandEvaluator& evaluator,
                                  const DetectorKeypointModel& model,
                                  const std::vector<int>& vertex_ids,
                                  const double* global_orient, const double* hand_pose,
                                  const double* betas, const double* transl,
                                  double* keypoints63, double* jacobian);

// The detector's keypoints of a posed mesh (PoseHand's), 21 x 3.
Points3d DetectorKeypointsOfMesh(const DetectorKeypointModel& model,
                                 const HandMesh& mesh);

// Per keypoint, the `count` mesh vertices nearest to it on the mean-shape, flat hand
// (ties by id): where LearnDetectorKeypoints looks.
std::array<std::vector<int>, kNumHandKeypoints> NearestVertexIds(const HandModel& model,
                                                                 int count);

// One training frame: the truth's parameters and the detector's keypoints in the same
// frame (triangulated), with which of them were found.
struct DetectorKeypointSample {
  HandParams truth;
  Points3d detected = Points3d::Zero(kNumHandKeypoints, 3);
  std::array<bool, kNumHandKeypoints> found{};
};

struct LearnDetectorKeypointsOptions {
  // Mesh vertices per keypoint: the nearest to the keypoint on the mean-shape, flat
  // hand (>= 1). More describe the skin around a joint better and need more frames.
  int vertices_per_keypoint = 12;
  // Ridge on the weights, relative to the mean squared vertex offset (>= 0): pulls
  // weights that the frames do not determine towards the model's keypoint.
  double ridge = 1e-3;
  // Samples farther than this many times the keypoint's median residual from the first
  // solution are dropped before the second (> 1): wrong detections, bad triangulations.
  double outlier_factor = 3.0;
  // Throws InputError naming `source` and the field.
  void Check(const std::string& source) const;
};

// Per keypoint, the weights that put D_k nearest (least squares) to the detections of
// the samples where it was found; throws InputError when a keypoint has fewer than 4
// samples. `detector` and `learned` are recorded in the model.
DetectorKeypointModel LearnDetectorKeypoints(
    const HandModel& hand_model, const std::vector<DetectorKeypointSample>& samples,
    const LearnDetectorKeypointsOptions& options, const std::string& detector,
    const std::string& learned);

// File I/O (JSON, format "handlabel-detector-keypoints", version 1). Reading throws
// InputError naming the file and field.
void WriteDetectorKeypointModel(const std::string& path,
                                const DetectorKeypointModel& model);
DetectorKeypointModel ReadDetectorKeypointModel(const std::string& path);

// A job field's setting (`fit.detector_keypoints`, `sequence.detector_keypoints`): "none"
// (nothing: the 2D marks the model's keypoints), "mediapipe" (the shipped
// models/detector_keypoints_mediapipe.json) or a model file. Throws InputError naming
// `source` and `field` when the file does not exist.
std::optional<DetectorKeypointModel> DetectorKeypointModelOfSetting(
    const std::string& setting, const std::string& source, const std::string& field);

}  // namespace handlabel
