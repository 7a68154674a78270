#pragma once
// Simulated 2D detector output for synthetic views: what a keypoint network and a
// segmentation network would give, derived from the exact ground truth.
//
// Per keypoint (21, SNAP order):
//   out of frame             dropped
//   dropout (probability by visibility)  dropped: confidence 0, position NaN
//   outlier (outlier_rate)   uniform in the hand's box enlarged by 50 %, confidence
//                            in [0.1, 0.6]
//   otherwise                ground truth + Gaussian noise (sigma px; x2 when
//                            occluded), confidence in [0.6, 1] visible, [0.2, 0.6]
//                            occluded
// Mask: the hand mask eroded or dilated by up to `mask_morph_radius` pixels, then
// `mask_blobs` random ellipses at the boundary added or cut out.

#include <random>

#include "capture/synth_view.h"
#include "core/image.h"
#include "core/keypoints2d.h"

namespace handlabel {

struct DetectionNoiseOptions {
  double keypoint_sigma_px = 2.0;      // Gaussian noise on visible keypoints (>= 0)
  double outlier_rate = 0.03;          // probability of a wild guess per keypoint
  double dropout_rate = 0.02;          // probability of a missing visible keypoint
  double occluded_dropout_rate = 0.3;  // same for occluded keypoints
  int mask_morph_radius = 2;           // max erosion/dilation of the noisy mask (px)
  int mask_blobs = 3;                  // max boundary blobs added or removed
  void Check() const;
};

struct ViewDetections {
  Keypoints2d keypoints;  // dropped ones: confidence 0, position NaN (as written)
  ImageU8 mask;           // 0/255
};

ViewDetections SimulateDetections(const SynthView& view,
                                  const DetectionNoiseOptions& options,
                                  std::mt19937_64& rng);

}  // namespace handlabel
