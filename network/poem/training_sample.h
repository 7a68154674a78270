#pragma once
// One multi-view training (or evaluation) sample for POEM, in plain C++ (no LibTorch),
// and the interface of whatever makes them. The trainer (poem_trainer.h) only sees this
// interface; training/training_samples.h implements it with synthetic captures made on
// the fly, so network/ never depends on pipeline/.
//
// Frames: the master frame is camera 0's (after augmentation); pixels are crop pixels
// of the S x S crop (centre of the top-left pixel at (0, 0)).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace handlabel {

struct TrainingView {
  // 3 x S x S (channel-major, RGB), values RGB / 255 - 0.5 (the network's input).
  std::vector<float> image;
  // S x S hand mask in [0, 1], or empty when masks were not requested.
  std::vector<float> mask;
  // Pinhole crop intrinsics (fx = fy, no skew) of the (augmented) view camera.
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();
  // Camera -> master frame (metres); identity for view 0.
  Eigen::Matrix4d master_from_cam = Eigen::Matrix4d::Identity();
  // The 21 keypoints (SNAP order) in crop pixels: exactly the projection of
  // TrainingSample::joints_3d through intrinsics and master_from_cam.
  Eigen::Matrix<double, 21, 2, Eigen::RowMajor> joints_2d =
      Eigen::Matrix<double, 21, 2, Eigen::RowMajor>::Zero();
  // Weight of each 2D keypoint in the losses (0 = behind the camera).
  std::array<float, 21> joints_2d_weight{};
  // Triangulation weight of the view (HandMeshViewInput::weight): 0 for a view whose
  // evidence did not locate the hand, which inference crops as the whole image and
  // leaves out of the triangulation; its 2D keypoints then count for nothing either.
  float view_weight = 1.0f;
};

struct TrainingSample {
  int64_t index = 0;  // sample index it was made for
  int64_t frame = 0;  // index of the synthetic frame it was cut from
  std::vector<TrainingView> views;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> joints_3d;    // 21 x 3
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertices_3d;  // V x 3
};

// A network's answer for one sample (master frame, metres).
struct PoemPrediction {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> joints_3d;    // 21 x 3
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertices_3d;  // V x 3
  // Per view, the mask head's hand probability on its M x M grid (M = crop size / 4,
  // row-major; cell (i, j) covers crop pixels [4j, 4j + 4) x [4i, 4i + 4)); empty
  // without a mask head.
  std::vector<std::vector<float>> masks;
};

// Intersection over union of predicted masks (probability > 0.5) with the samples'
// crop masks (4 x 4 block coverage > 0.5), pooled over every cell added.
struct MaskIouCounts {
  double intersection = 0;
  double union_cells = 0;
  // Adds one view: `probability` M x M, `crop_mask` S x S with S = 4 M.
  void Add(const std::vector<float>& probability, const std::vector<float>& crop_mask);
  // Adds every view of every sample that has both; returns false if none had.
  bool Add(const PoemPrediction& prediction, const TrainingSample& sample);
  double Iou() const { return union_cells > 0 ? intersection / union_cells : 1.0; }
};

// Makes samples; Sample(i) must depend only on i (and the source's settings) and be
// callable from any thread.
class TrainingSampleSource {
 public:
  virtual ~TrainingSampleSource() = default;
  virtual int num_views() const = 0;
  virtual int crop_size() const = 0;
  virtual TrainingSample Sample(int64_t index) const = 0;
};

// Samples [first, end) of `source`, in index order (one batch).
std::vector<TrainingSample> SampleRange(const TrainingSampleSource& source, int64_t first,
                                        int64_t end);

}  // namespace handlabel
