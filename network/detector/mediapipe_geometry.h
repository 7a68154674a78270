#pragma once
// The model-free steps of MediaPipe's hand pipeline (graphs hand_landmark_tracking_gpu,
// palm_detection_gpu, hand_landmark_gpu of the @mediapipe/hands 0.4.1675469240 package),
// written from the graphs' calculator options:
//   SSD anchors of the 192x192 palm model; decoding of its 2016 boxes + 7 keypoints with
//   sigmoid scores; weighted non-maximum suppression; letterbox removal; the rotated hand
//   ROI from a palm; the image-to-tensor crop (letterbox, rotation, bilinear sampling,
//   border modes as the WebGL converter samples); landmark projection back to the image.
// Coordinates named *_norm are normalised to the full image ([0, 1] across its width and
// height, as MediaPipe's NormalizedRect). Pixel positions follow handlabel's convention
// (centre of the top-left pixel at (0, 0)); MediaPipe's normalised x maps to pixel
// x * width - 0.5.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "image/image.h"

namespace handlabel {

inline constexpr int kPalmKeypoints = 7;  // wrist, index/middle/ring/pinky MCP, thumb x2
inline constexpr int kPalmModelInputSize = 192;
inline constexpr int kHandLandmarkInputSize = 224;

// SsdAnchorsCalculator options; defaults are the palm model's (palm_detection_gpu.pbtxt).
struct SsdAnchorOptions {
  // Model input size in pixels.
  int input_width = kPalmModelInputSize;
  int input_height = kPalmModelInputSize;
  // Anchor scales (unused for the centres with fixed-size anchors, kept for the count).
  double min_scale = 0.1484375;
  double max_scale = 0.75;
  // Anchor centre offset inside a feature-map cell, in cells.
  double anchor_offset_x = 0.5;
  double anchor_offset_y = 0.5;
  // One stride per layer; consecutive layers with equal strides share one grid.
  std::vector<int> strides = {8, 16, 16, 16};
  // Anchors per layer and cell: one per aspect ratio plus one interpolated scale.
  int anchors_per_layer_cell = 2;
  // Throws InputError naming `source` when a field is out of range.
  void Check(const std::string& source) const;
};

// Anchor centres, normalised to the model input, in the model's output order.
std::vector<Eigen::Vector2d> MakeSsdAnchors(const SsdAnchorOptions& options = {});

// A palm, normalised to whatever frame the step works in (model input before letterbox
// removal, full image after it).
struct PalmDetection {
  double score = 0;  // sigmoid of the clipped raw score
  double xmin = 0, ymin = 0, width = 0, height = 0;
  std::array<Eigen::Vector2d, kPalmKeypoints> keypoints{};
};

// TensorsToDetectionsCalculator options of the palm model.
struct PalmDecodeOptions {
  // Raw box/keypoint values are in model-input pixels: divided by this scale.
  double coordinate_scale = kPalmModelInputSize;
  // Raw scores are clipped to +-this before the sigmoid.
  double score_clipping = 100.0;
  // Boxes scoring below this are dropped (MediaPipe's min_detection_confidence).
  double min_score = 0.5;
  void Check(const std::string& source) const;
};

// Decodes the palm model's outputs: `boxes` holds anchors.size() x 18 floats (box centre
// x, y, w, h, then 7 keypoints x, y, relative to the anchor centre, in input pixels),
// `scores` one logit per anchor. Returns the boxes scoring >= min_score with a
// non-negative size, in anchor order.
std::vector<PalmDetection> DecodePalms(const std::vector<float>& boxes,
                                       const std::vector<float>& scores,
                                       const std::vector<Eigen::Vector2d>& anchors,
                                       const PalmDecodeOptions& options = {});

// Intersection over union of two detections' boxes (0 when the union is empty).
double BoxIou(const PalmDetection& a, const PalmDetection& b);

// MediaPipe's WEIGHTED non-maximum suppression: the highest-scoring remaining detection
// takes every remaining one overlapping it by IoU > `iou_threshold` (itself included)
// and becomes their score-weighted mean box and keypoints, keeping its own score.
// Output in decreasing score order.
std::vector<PalmDetection> WeightedNonMaxSuppression(
    std::vector<PalmDetection> detections, double iou_threshold = 0.3);

// Letterbox padding of a keep-aspect-ratio crop, as fractions of the padded size.
struct LetterboxPadding {
  double left = 0, top = 0, right = 0, bottom = 0;
};

// A rotated rectangle in pixels: centre (MediaPipe's continuous coordinates: 0 is the
// image's left edge, so pixel centres sit at k + 0.5), size, rotation in radians
// (clockwise on screen, as y points down).
struct RotatedRect {
  double x_center = 0, y_center = 0, width = 0, height = 0, rotation = 0;
};

// The same rectangle normalised to an image of the given size.
struct NormalizedRect {
  double x_center = 0, y_center = 0, width = 0, height = 0, rotation = 0;
  RotatedRect ToPixels(int image_width, int image_height) const;
};

// Maps a detection from the letterboxed model frame to the unpadded image frame.
PalmDetection RemoveLetterbox(const PalmDetection& detection,
                              const LetterboxPadding& pad);

// A square tile of an image for palm detection over tiles: left and top edge and side,
// in MediaPipe's continuous pixel coordinates (0 = the image's left edge).
struct PalmTile {
  double left = 0, top = 0, side = 0;
  RotatedRect ToRect() const {
    return {left + side / 2, top + side / 2, side, side, 0.0};
  }
};

// `across` square tiles along the image's shorter side and as many along the longer
// side as it takes, covering the image, neighbours overlapping by at least `overlap`
// of a tile side (spread evenly, so the first and last tiles touch the image edges).
// A palm smaller than the overlap lies whole in some tile. across >= 1; one tile when
// the image is square and across is 1.
std::vector<PalmTile> MakePalmTiles(int image_width, int image_height, int across,
                                    double overlap = 0.25);

// A detection normalised to `tile` mapped to the image's normalised coordinates.
PalmDetection TileToImage(const PalmDetection& detection, const PalmTile& tile,
                          int image_width, int image_height);

// DetectionsToRects + RectTransformation of palm_detection_detection_to_roi: the hand ROI
// from a palm (normalised to the full image).
struct HandRoiOptions {
  // Keypoints whose direction sets the rotation: wrist (0) to middle-finger MCP (2).
  int rotation_start_keypoint = 0;
  int rotation_end_keypoint = 2;
  // The rotation makes that direction point this way (90 degrees: up in the crop).
  double target_angle_deg = 90.0;
  // Box scale and shift along the rotated box's own axes, in box sizes.
  double scale = 2.6;
  double shift_x = 0.0;
  double shift_y = -0.5;
  void Check(const std::string& source) const;
};
NormalizedRect HandRoiFromPalm(const PalmDetection& palm, int image_width,
                               int image_height, const HandRoiOptions& options = {});

enum class BorderMode { kZero, kReplicate };

// ImageToTensorCalculator on the GPU: the `roi` of `image` (RGB) into a width x height
// x 3 tensor (row-major HWC floats in [0, 1]). With keep_aspect_ratio the ROI is first
// enlarged to the tensor's aspect ratio and the enlargement is returned as padding.
// Output pixel (i, j) samples the image bilinearly at the ROI point under its centre;
// outside the image: zeros (kZero) or the edge pixels (kReplicate).
struct TensorCrop {
  std::vector<float> values;
  LetterboxPadding padding;
};
TensorCrop CropToTensor(const ImageU8& image, const RotatedRect& roi, int width,
                        int height, bool keep_aspect_ratio, BorderMode border);

// The ROI enlarged to the tensor aspect ratio (height / width) and the padding that adds.
RotatedRect PadRoi(const RotatedRect& roi, double tensor_aspect,
                   LetterboxPadding* padding);

// A point in crop-normalised coordinates ([0, 1] across the tensor, letterbox included)
// mapped to the image's normalised coordinates through `roi` (normalised) after removing
// the letterbox padding: LandmarkLetterboxRemoval + LandmarkProjection.
Eigen::Vector2d ProjectCropPoint(const Eigen::Vector2d& crop_norm,
                                 const NormalizedRect& roi,
                                 const LetterboxPadding& padding);

// The ROI around projected keypoints (pixels, distorted), MediaPipe's tracking rule
// (hand_landmark_landmarks_to_roi, on its subset of joints 0-3, 5, 6, 9, 10, 13, 14, 17,
// 18): rotation from the wrist to the mean of the index, middle and ring MCPs, the box
// of those joints in that rotated frame, shifted 0.1 box heights towards the fingers,
// squared on the long side and scaled by 2. `uv_px`: 21 keypoints, SNAP order, pixels.
NormalizedRect RoiFromKeypoints(
    const Eigen::Matrix<double, 21, 2, Eigen::RowMajor>& uv_px, int image_width,
    int image_height);

// Pixel position (handlabel convention) of a normalised image point.
inline Eigen::Vector2d NormToPixel(const Eigen::Vector2d& norm, int width, int height) {
  return {norm.x() * width - 0.5, norm.y() * height - 0.5};
}

}  // namespace handlabel
