#pragma once
// Outline samples of a silhouette mask and their matching to projected vertices, for
// the mask -> mesh half of the silhouette term (silhouette_cost.h).

#include <Eigen/Core>
#include <vector>

#include "image/distance_transform.h"

namespace handlabel {

struct MaskOutline {
  std::vector<Eigen::Vector2d> points;   // on the pixel edge between inside and outside
  std::vector<Eigen::Vector2d> normals;  // unit, pointing out of the mask
};

// Mask pixels with a 4-neighbour outside the mask (pixels on the image border are not
// outline: the hand continues beyond the image), evenly subsampled in scan order to at
// most `max_samples`; each point is moved half a pixel along its outward normal (from
// the centroid of the mask pixels in a 7x7 window towards the pixel). With an
// `occluder` mask of the same size, mask pixels within `occluder_reach_px` (Chebyshev)
// of an occluder pixel are not outline either: there the hand may continue behind the
// occluder.
MaskOutline SampleMaskOutline(const MaskImage& mask, int max_samples,
                              const MaskImage* occluder = nullptr,
                              int occluder_reach_px = 2);

// For every outline point, the index (into `projected`) of the nearest projected point;
// entries with valid[i] == 0 are skipped. -1 if none is valid.
std::vector<int> MatchOutlineToPoints(const MaskOutline& outline,
                                      const std::vector<Eigen::Vector2d>& projected,
                                      const std::vector<char>& valid);

// How far the mask's outline lies outside the projected hand's, in pixels (positive:
// the mask is larger, e.g. dilated; negative: eroded): the median over the matched
// outline samples (`matched` from MatchOutlineToPoints) of n . (p - projected[c]).
// 0 when no sample is matched. Segmentation masks are often uniformly too fat or too
// thin; the median ignores the samples where the fit or the mask is locally off.
double EstimateMaskMargin(const MaskOutline& outline, const std::vector<int>& matched,
                          const std::vector<Eigen::Vector2d>& projected);

// The outline moved inwards by `margin_px` along its normals (outwards if negative).
std::vector<Eigen::Vector2d> ShiftedOutline(const MaskOutline& outline, double margin_px);

}  // namespace handlabel
