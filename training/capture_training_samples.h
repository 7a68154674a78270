#pragma once
// POEM training samples cut from a real capture whose frames carry labels (for example
// the labels of a detector + fit job on that same capture): the network learns the
// user's cameras, lighting and hands from the slow method's answers (issue 43).
//
// Sample i is cut from labelled frame Order(i): the frames in a fresh random order in
// every epoch of `frames.size()` samples. For each view:
//   window  with probability detection_crop_probability, what inference crops: the
//           window around the frame's detected 2D keypoints (CropFromKeypoints, the
//           network stage's rule), or the whole image at view weight 0 where they do
//           not locate the hand; otherwise the window around the label's keypoints
//           projected into the view (CropFromPrior), its side x augment scale, its
//           centre shifted by N(0, shift_sigma) x side per axis (clipped at 2 sigma).
//           A sample keeps at least two views of weight 1 (the triangulation needs
//           them): if the detections leave fewer, the others take label windows.
//   crop    CropIntrinsics + WarpCrop (network/poem/hand_crop.h), exactly as inference:
//           any camera model, distortion removed by the warp.
//   pixels  when augmenting: Gaussian blur of sigma U(0, blur_max_px), pixel noise of
//           sigma U(0, noise_max) levels, then per-channel gain and the noise rectangle
//           (view_augmentation.h).
//   targets the label's keypoints through the view's camera and the crop intrinsics;
//           master_from_cam as the network stage builds it; keypoints and vertices in
//           the master frame (camera 0).
// No in-plane rotation.
// Everything random derives from (seed, i), so Sample(i) is the same on every call and
// every thread. Labels arrive as plain arrays: reading label files is pipeline/'s job.

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "core/point_arrays.h"
#include "network/poem/hand_crop.h"
#include "network/poem/training_sample.h"
#include "training/view_augmentation.h"

namespace handlabel {

// One labelled frame of a capture, in the rig's world frame (metres).
struct LabeledFrame {
  std::string id;         // the frame source's frame id
  Points3d keypoints_3d;  // 21 x 3, SNAP order
  Points3d vertices;      // V x 3, the network's mesh (778 for MANO topology)
};

struct CaptureSampleOptions {
  int crop_size = 128;  // crop side in pixels, the network's (a multiple of 32)
  // Chance that a view is cropped as inference crops it, around its detected 2D
  // keypoints or, where they miss the hand, whole at weight 0 (0..1); otherwise around
  // the label's projected keypoints, with jitter.
  double detection_crop_probability = 0.5;
  // Label-window crops: centre shift per axis, N(0, shift_sigma) x window side,
  // clipped at 2 sigma (0..0.5).
  double shift_sigma = 0.05;
  double blur_max_px = 1.2;  // blur sigma ~ U(0, blur_max_px) crop pixels (0..5)
  double noise_max = 6;      // pixel noise sigma ~ U(0, noise_max) levels of 255 (0..50)
  // Scale jitter of label windows, gain and noise rectangle (view_augmentation.h);
  // enabled false: plain crops, no blur and no noise (validation). Crops from captures
  // are not turned: rotation_probability must be 0.
  TrainingAugmentOptions augment = [] {
    TrainingAugmentOptions a;
    a.rotation_probability = 0;
    return a;
  }();
  uint64_t seed = 0;  // frame order and augmentation
  void Check(const std::string& source) const;
};

// The random choices for one view of one sample.
struct CaptureViewDraws {
  ViewAugmentation augmentation;  // scale (label windows), gain, noise rectangle
  bool from_detection = false;    // crop around the detected keypoints if they locate
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();  // label window, fraction of side
  double blur_sigma_px = 0;
  double noise_sigma = 0;
  uint64_t noise_seed = 0;
};
CaptureViewDraws DrawCaptureView(const CaptureSampleOptions& options,
                                 std::mt19937_64& rng);

// The source window of view v and the view's triangulation weight. With
// draws.from_detection and a detection entry for the view: the window around the
// detected keypoints when they locate the hand, else, as inference, the whole image at
// weight 0. Otherwise (or without detections for the view) the window around the
// projected label keypoints, jittered, at weight 1; the whole image at weight 1 when
// the label is behind the camera or outside the image.
struct CaptureViewCrop {
  CropWindow window;
  float weight = 1.0f;
};
CaptureViewCrop CaptureViewWindow(const FrameInput& frame, size_t v,
                                  const Points3d& keypoints_world,
                                  const CaptureViewDraws& draws,
                                  const HandCropOptions& crop);

class CaptureTrainingSamples : public TrainingSampleSource {
 public:
  // Keeps a reference to `source`, which must outlive this object. Throws InputError
  // naming the field for bad options, no frames, or a label that is not 21 finite
  // keypoints and finite vertices.
  CaptureTrainingSamples(const FrameSource& source, std::vector<LabeledFrame> frames,
                         const CaptureSampleOptions& options);
  int num_views() const override { return num_views_; }
  int crop_size() const override { return options_.crop_size; }
  // Reads and crops the frame's images; throws InputError naming the frame for a
  // missing image or a rig of another size.
  TrainingSample Sample(int64_t index) const override;

  // Position in the frame list of the frame that sample `index` is cut from.
  size_t FrameOfSample(int64_t index) const;
  // The share of the frames' views that inference would cut as missed (no detected
  // keypoints, or too few to locate the hand: whole image, weight 0). Synthetic
  // samples drop views at this rate to look like the capture (view_dropout).
  double MissedViewShare() const;
  const std::vector<LabeledFrame>& frames() const { return frames_; }

 private:
  void MakeView(const FrameInput& frame, size_t v, const LabeledFrame& label,
                const CaptureViewDraws& draws, const CaptureViewCrop& crop,
                TrainingView* view) const;

  const FrameSource& source_;
  std::vector<LabeledFrame> frames_;
  CaptureSampleOptions options_;
  HandCropOptions crop_;  // inference's crop rules at options_.crop_size
  int num_views_ = 0;
};

}  // namespace handlabel
