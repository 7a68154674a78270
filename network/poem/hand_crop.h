#pragma once
// Per-view input crops for hand networks (torch-free): a square window around the
// hand, the crop's pinhole intrinsics, and the warp into a normalised float image.
//
// The crop is a virtual pinhole camera with the source camera's rotation: crop pixel
// (x', y') looks along K_crop^-1 (x', y', 1), and the warp samples the source image
// where that ray lands *with* the source camera's distortion, so distorted cameras
// give undistorted crops and K_crop is exact. Pixel centres are at integer coordinates
// in both images; the window centre maps to (S/2, S/2), as the reference's affine crop.
//
// Where the window comes from, in order of preference (CropForView):
//   1. 2D detections of the hand in this view (keypoints with confidences, or a box),
//   2. a 3D prior (e.g. the previous frame's joints) projected into the view,
//   3. the whole image.
// A view whose evidence does not locate the hand is marked not visible: it still gets
// a crop (the network needs every view) but its triangulation weight should be 0.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "hand/keypoints2d.h"
#include "image/distance_transform.h"

namespace handlabel {

struct CropWindow {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // source image pixels
  double side = 0;                                   // source image pixels
};

struct HandCropOptions {
  int crop_size = 256;          // output side S in pixels
  double box_scale = 2.0;       // window side = box_scale * longer side of the hand box
  double min_side_px = 32;      // smallest window side in source pixels
  double min_confidence = 0.3;  // keypoints below this are ignored
  int min_keypoints = 4;        // fewer confident keypoints -> no window from keypoints
  // The RGB normalisation of the reference: (value / 255 - mean) / std per channel.
  double mean = 0.5;
  double std = 1.0;
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

// Window around an axis-aligned box (min and max corner, pixels).
CropWindow CropFromBox(const Eigen::Vector2d& box_min, const Eigen::Vector2d& box_max,
                       const HandCropOptions& options);
// Window around the confident keypoints (full-image pixels); nullopt if fewer than
// options.min_keypoints.
std::optional<CropWindow> CropFromKeypoints(const Keypoints2d& keypoints,
                                            const HandCropOptions& options);
// Window around the projection of 3D points (camera frame of `camera`); nullopt if
// fewer than two points project in front of the camera or the box misses the image.
std::optional<CropWindow> CropFromPrior(const Camera& camera,
                                        const std::vector<Eigen::Vector3d>& points_in_cam,
                                        const HandCropOptions& options);
// Square around the whole image (side = the longer image side).
CropWindow WholeImageCrop(const Camera& camera);

// The 3x3 pinhole intrinsics of the crop (a virtual camera with the same rotation).
Eigen::Matrix3d CropIntrinsics(const Camera& camera, const CropWindow& window,
                               int crop_size);

// Interleaved 8-bit RGB image, row-major, pixel (x, y) at data[(y * width + x) * 3].
struct RgbImageView {
  int width = 0;
  int height = 0;
  const uint8_t* data = nullptr;
};

// Warps the window to crop_size^2 pixels, bilinear, zero outside the image, and
// normalises: out[c * S * S + y * S + x] = (value / 255 - mean) / std (channels RGB).
std::vector<float> WarpCrop(const RgbImageView& image, const Camera& camera,
                            const CropWindow& window, const HandCropOptions& options);

struct ViewCrop {
  CropWindow window;
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();
  std::vector<float> pixels;  // 3 x S x S, normalised
  // False when evidence was given but did not locate the hand (whole-image fallback):
  // give the view DLT weight 0. True when located, or when no evidence was given.
  bool hand_visible = false;
  std::string source;  // "keypoints", "box", "prior" or "whole image"
};

// Per-view evidence of where the hand is; all optional.
struct HandEvidence {
  std::optional<Keypoints2d> keypoints;  // 2D detections (full-image pixels)
  std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> box;  // min, max corner
  std::vector<Eigen::Vector3d> prior_points_in_cam;  // e.g. last frame's joints
};

// Chooses the window (keypoints, box, prior, whole image), computes the intrinsics and
// warps the image.
ViewCrop CropForView(const RgbImageView& image, const Camera& camera,
                     const HandEvidence& evidence, const HandCropOptions& options);

// The inverse direction, for a mask predicted on a coarse grid over a crop
// (hand_mesh_predictor.h HandMeshPrediction::masks: M x M cells of `cell` crop pixels,
// M * cell = crop side): the full-image mask (camera size; 255 where the bilinearly
// interpolated probability exceeds `threshold`, 0 elsewhere and outside the crop).
// Each image pixel is undistorted to its ray and projected with K_crop, so distorted
// cameras are exact, as in WarpCrop.
MaskImage CropMaskToImage(const Eigen::MatrixXf& probability, int cell,
                          const Eigen::Matrix3d& crop_intrinsics, const Camera& camera,
                          double threshold = 0.5);

}  // namespace handlabel
