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
// Behind an object (SynthView::behind_object), a detector guesses the keypoint from
// the visible hand around the object, and the guess gets worse the deeper the keypoint
// lies inside the object: with d the distance (px) from the keypoint to the nearest
// visible hand pixel (object_depth_cap_px when no hand pixel is visible),
//   noise sigma  2 sigma + object_sigma_per_px * d
//   confidence   (0.2 + 0.4 u) / (1 + d / object_confidence_px),  u uniform in [0, 1)
// so a keypoint 20 px inside an object gets sigma 2 * 2 + 0.25 * 20 = 9 px and at most
// 0.6 / 1.67 = 0.36 confidence with the defaults.
// Mask: the hand mask eroded or dilated by up to `mask_morph_radius` pixels, then
// `mask_blobs` random ellipses at the boundary added or cut out.

#include <array>
#include <random>

#include "capture/synth_view.h"
#include "hand/keypoints2d.h"
#include "image/image.h"

namespace handlabel {

struct DetectionNoiseOptions {
  double keypoint_sigma_px = 2.0;      // Gaussian noise on visible keypoints (>= 0)
  double outlier_rate = 0.03;          // probability of a wild guess per keypoint
  double dropout_rate = 0.02;          // probability of a missing visible keypoint
  double occluded_dropout_rate = 0.3;  // same for occluded keypoints
  // Keypoints behind an object (see above): extra noise per pixel of depth into the
  // object (>= 0), the depth that halves the confidence (px, > 0), and the depth
  // assumed when the view shows no hand pixel at all (px, >= 0).
  double object_sigma_per_px = 0.25;
  double object_confidence_px = 30.0;
  double object_depth_cap_px = 60.0;
  int mask_morph_radius = 2;  // max erosion/dilation of the noisy mask (px)
  int mask_blobs = 3;         // max boundary blobs added or removed
  void Check(const std::string& source) const;
};

struct ViewDetections {
  Keypoints2d keypoints;  // dropped ones: confidence 0, position NaN (as written)
  ImageU8 mask;           // 0/255
};

// The depth d (px) of each keypoint behind an object, 0 for the others: the distance
// to the nearest visible hand pixel, at most `cap_px`.
std::array<double, kNumHandKeypoints> DepthBehindObjects(const SynthView& view,
                                                         double cap_px);

ViewDetections SimulateDetections(const SynthView& view,
                                  const DetectionNoiseOptions& options,
                                  std::mt19937_64& rng);

}  // namespace handlabel
