#pragma once
// POEM training samples cut from synthetic captures made on the fly
// (capture/synth_capture.h): per-view hand crops with their crop intrinsics, the
// camera -> master extrinsics, and exact targets (21 keypoints and all vertices in the
// master frame, 2D keypoints per view in crop pixels).
//
// Crop: a square of side box_scale x the larger side of the hand's 2D keypoint box,
// centred on the box, resampled bilinearly to crop_size x crop_size (zero border).
// Augmentation (the reference recipe, docs/training.md), per view:
//   scale      crop side x s, s ~ N(1, scale_sigma) clipped to 1 +- 2 scale_sigma
//   rotation   with probability rotation_probability the crop turns by
//              N(0, rotation_sigma_deg) about its centre; the turn is folded into the
//              extrinsic (a rotation of the camera about its optical axis) so that the
//              crop intrinsics stay pinhole and the 3D targets project exactly onto the
//              2D targets. Turning view 0 turns the master frame with it.
//   colour     per-channel gain U(gain_min, gain_max)
//   noise      with probability noise_rect_probability a rectangle of uniform noise
// Crops always have fx = fy: the box is resampled anisotropically by f / fx, f / fy
// (f = mean focal) first, which is exact and a no-op for square pixels.
//
// Sample i is cut from frame FrameOf(i): `frame_reuse` consecutive groups of
// `reuse_group` samples share the same `reuse_group` frames (with fresh augmentation),
// so rendering costs 1 / frame_reuse of a frame per sample. Everything random derives
// from (seed, i), so Sample(i) is the same on every call and every thread.

#include <cstdint>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "capture/synth_capture.h"
#include "hand/hand_model.h"
#include "network/poem/training_sample.h"
#include "training/view_augmentation.h"

namespace handlabel {

struct TrainingSampleOptions {
  int crop_size = 128;        // output crop side in pixels (multiple of 32)
  double box_scale = 2.0;     // crop side / larger side of the 2D keypoint box (> 0)
  double min_box_px = 16;     // smallest keypoint box side used, pixels (> 0)
  bool masks = false;         // also crop the hand masks
  int frame_reuse = 1;        // samples cut from each rendered frame (>= 1)
  int reuse_group = 1;        // samples per reuse group, e.g. the batch size (>= 1)
  uint64_t augment_seed = 0;  // mixed with the sample index for the augmentation
  // Chance that a view is cut as inference cuts a view whose detection missed the hand:
  // the whole image at view weight 0 (0..1). At least two views per sample keep weight
  // 1 (the network triangulates from them). 0 draws nothing, so samples stay as before.
  double view_dropout = 0;
  TrainingAugmentOptions augment;
  void Check(const std::string& source) const;
};

// The synthetic frame that sample `index` is cut from.
int64_t TrainingFrameOf(int64_t index, const TrainingSampleOptions& options);

// The views of one sample cut as missed detections: each with chance `view_dropout`,
// then dropped views, in random order, restored until two keep weight 1 (every view
// with fewer than three cameras). Draws nothing when view_dropout is 0.
std::vector<bool> DrawMissedViews(double view_dropout, int num_views,
                                  std::mt19937_64& rng);

// Cuts one sample out of a frame. `rig` is the generator's rig (pinhole cameras).
// `missed` (empty = none) marks views cut as a missed detection: the whole image
// (network/poem/hand_crop.h WholeImageCrop), no scale jitter or turn, view weight 0.
// Throws InputError if a camera has lens distortion.
TrainingSample MakeTrainingSample(const SynthFrame& frame, const Rig& rig,
                                  const TrainingSampleOptions& options,
                                  const std::vector<ViewAugmentation>& augmentations,
                                  const std::vector<bool>& missed = {});

// TrainingSampleSource over a SynthGenerator. Keeps the frames of the last reuse group
// so consecutive samples do not render them again.
class SynthTrainingSamples : public TrainingSampleSource {
 public:
  // Depth rendering and detections are switched off in `synth` (not needed).
  SynthTrainingSamples(const HandModel& model, const SynthCaptureOptions& synth,
                       const TrainingSampleOptions& options);
  // On the given rig (pinhole cameras, e.g. a capture's own) instead of synth.rig's.
  SynthTrainingSamples(const HandModel& model, Rig rig, const SynthCaptureOptions& synth,
                       const TrainingSampleOptions& options);
  int num_views() const override { return static_cast<int>(generator_.rig().size()); }
  int crop_size() const override { return options_.crop_size; }
  TrainingSample Sample(int64_t index) const override;

  const SynthGenerator& generator() const { return generator_; }
  const TrainingSampleOptions& options() const { return options_; }

 private:
  std::shared_ptr<const SynthFrame> Frame(int64_t frame_index) const;

  SynthGenerator generator_;
  TrainingSampleOptions options_;
  mutable std::mutex cache_mutex_;
  mutable std::vector<std::pair<int64_t, std::shared_ptr<const SynthFrame>>> cache_;
};

}  // namespace handlabel
