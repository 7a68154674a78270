#include "network/detector/mediapipe_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kPalmValuesPerAnchor = 4 + 2 * kPalmKeypoints;
// The palm and lower finger joints the tracking ROI is built from.
constexpr int kRoiJoints[] = {0, 1, 2, 3, 5, 6, 9, 10, 13, 14, 17, 18};

// MediaPipe's NormalizeRadians: into [-pi, pi).
double NormalizeRadians(double angle) {
  return angle - 2 * kPi * std::floor((angle + kPi) / (2 * kPi));
}

double Sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

// One colour sample with clamp-to-edge bilinear filtering (GL_LINEAR, CLAMP_TO_EDGE) at
// pixel position (x, y), handlabel convention.
void SampleBilinear(const ImageU8& image, double x, double y, float* rgb) {
  const double fx0 = std::floor(x);
  const double fy0 = std::floor(y);
  const double ax = x - fx0;
  const double ay = y - fy0;
  const auto clamp_x = [&](double v) {
    return std::clamp(static_cast<int>(v), 0, image.width - 1);
  };
  const auto clamp_y = [&](double v) {
    return std::clamp(static_cast<int>(v), 0, image.height - 1);
  };
  const int x0 = clamp_x(fx0), x1 = clamp_x(fx0 + 1);
  const int y0 = clamp_y(fy0), y1 = clamp_y(fy0 + 1);
  for (int c = 0; c < 3; ++c) {
    const double top = (1 - ax) * image.at(x0, y0, c) + ax * image.at(x1, y0, c);
    const double bottom = (1 - ax) * image.at(x0, y1, c) + ax * image.at(x1, y1, c);
    rgb[c] = static_cast<float>(((1 - ay) * top + ay * bottom) / 255.0);
  }
}

}  // namespace

void SsdAnchorOptions::Check(const std::string& source) const {
  if (input_width <= 0 || input_height <= 0) {
    throw InputError(source, "input size", "positive width and height");
  }
  if (strides.empty()) throw InputError(source, "strides", "at least one stride");
  for (int s : strides) RequireGreater(source, "strides", s, 0, "positive strides");
  RequireGreater(source, "anchors_per_layer_cell", anchors_per_layer_cell, 0,
                 "a positive count");
}

std::vector<Eigen::Vector2d> MakeSsdAnchors(const SsdAnchorOptions& options) {
  options.Check("SsdAnchorOptions");
  std::vector<Eigen::Vector2d> anchors;
  const int num_layers = static_cast<int>(options.strides.size());
  for (int layer = 0; layer < num_layers;) {
    // Layers with the same stride share one grid; each adds its anchors to every cell.
    int same_stride_end = layer;
    while (same_stride_end < num_layers &&
           options.strides[same_stride_end] == options.strides[layer]) {
      ++same_stride_end;
    }
    const int per_cell = (same_stride_end - layer) * options.anchors_per_layer_cell;
    const int stride = options.strides[layer];
    const int grid_h = (options.input_height + stride - 1) / stride;
    const int grid_w = (options.input_width + stride - 1) / stride;
    for (int y = 0; y < grid_h; ++y) {
      for (int x = 0; x < grid_w; ++x) {
        const Eigen::Vector2d centre((x + options.anchor_offset_x) / grid_w,
                                     (y + options.anchor_offset_y) / grid_h);
        for (int k = 0; k < per_cell; ++k) anchors.push_back(centre);
      }
    }
    layer = same_stride_end;
  }
  return anchors;
}

void PalmDecodeOptions::Check(const std::string& source) const {
  RequireGreater(source, "coordinate_scale", coordinate_scale, 0);
  RequireGreater(source, "score_clipping", score_clipping, 0);
  RequireInRange(source, "min_score", min_score, 0, 1, "a value in [0, 1]");
}

std::vector<PalmDetection> DecodePalms(const std::vector<float>& boxes,
                                       const std::vector<float>& scores,
                                       const std::vector<Eigen::Vector2d>& anchors,
                                       const PalmDecodeOptions& options) {
  options.Check("PalmDecodeOptions");
  const size_t n = anchors.size();
  HL_CHECK(boxes.size() == n * kPalmValuesPerAnchor && scores.size() == n,
           "palm model outputs do not match the anchors");
  const double s = options.coordinate_scale;
  std::vector<PalmDetection> out;
  for (size_t i = 0; i < n; ++i) {
    const double raw = std::clamp(static_cast<double>(scores[i]), -options.score_clipping,
                                  options.score_clipping);
    const double score = Sigmoid(raw);
    if (score < options.min_score) continue;
    const float* v = &boxes[i * kPalmValuesPerAnchor];
    const Eigen::Vector2d& a = anchors[i];  // fixed-size anchors: width = height = 1
    PalmDetection d;
    d.score = score;
    const double xc = v[0] / s + a.x(), yc = v[1] / s + a.y();
    d.width = v[2] / s;
    d.height = v[3] / s;
    d.xmin = xc - d.width / 2;
    d.ymin = yc - d.height / 2;
    for (int k = 0; k < kPalmKeypoints; ++k) {
      d.keypoints[k] =
          Eigen::Vector2d(v[4 + 2 * k] / s + a.x(), v[5 + 2 * k] / s + a.y());
    }
    if (!(d.width >= 0) || !(d.height >= 0)) continue;  // also drops NaN
    out.push_back(d);
  }
  return out;
}

double BoxIou(const PalmDetection& a, const PalmDetection& b) {
  const double ix =
      std::min(a.xmin + a.width, b.xmin + b.width) - std::max(a.xmin, b.xmin);
  const double iy =
      std::min(a.ymin + a.height, b.ymin + b.height) - std::max(a.ymin, b.ymin);
  const double inter = (ix > 0 && iy > 0) ? ix * iy : 0.0;
  const double uni = a.width * a.height + b.width * b.height - inter;
  return uni > 0 ? inter / uni : 0.0;
}

std::vector<PalmDetection> WeightedNonMaxSuppression(
    std::vector<PalmDetection> detections, double iou_threshold) {
  std::stable_sort(
      detections.begin(), detections.end(),
      [](const PalmDetection& a, const PalmDetection& b) { return a.score > b.score; });
  std::vector<PalmDetection> out;
  std::vector<PalmDetection> remaining = std::move(detections);
  while (!remaining.empty()) {
    const PalmDetection top = remaining.front();
    std::vector<PalmDetection> rest;
    double total = 0, xmin = 0, ymin = 0, xmax = 0, ymax = 0;
    std::array<Eigen::Vector2d, kPalmKeypoints> keypoints;
    keypoints.fill(Eigen::Vector2d::Zero());
    for (const PalmDetection& d : remaining) {
      if (BoxIou(d, top) <= iou_threshold) {
        rest.push_back(d);
        continue;
      }
      total += d.score;
      xmin += d.xmin * d.score;
      ymin += d.ymin * d.score;
      xmax += (d.xmin + d.width) * d.score;
      ymax += (d.ymin + d.height) * d.score;
      for (int k = 0; k < kPalmKeypoints; ++k) keypoints[k] += d.keypoints[k] * d.score;
    }
    PalmDetection merged = top;
    if (total > 0) {
      merged.xmin = xmin / total;
      merged.ymin = ymin / total;
      merged.width = xmax / total - merged.xmin;
      merged.height = ymax / total - merged.ymin;
      for (int k = 0; k < kPalmKeypoints; ++k) merged.keypoints[k] = keypoints[k] / total;
    }
    out.push_back(merged);
    // A degenerate top box (zero area) overlaps nothing, itself included: MediaPipe
    // stops.
    if (rest.size() == remaining.size()) break;
    remaining = std::move(rest);
  }
  return out;
}

RotatedRect NormalizedRect::ToPixels(int image_width, int image_height) const {
  return {x_center * image_width, y_center * image_height, width * image_width,
          height * image_height, rotation};
}

PalmDetection RemoveLetterbox(const PalmDetection& detection,
                              const LetterboxPadding& pad) {
  const double sx = 1.0 - pad.left - pad.right;
  const double sy = 1.0 - pad.top - pad.bottom;
  PalmDetection d = detection;
  d.xmin = (detection.xmin - pad.left) / sx;
  d.ymin = (detection.ymin - pad.top) / sy;
  d.width = detection.width / sx;
  d.height = detection.height / sy;
  for (auto& k : d.keypoints)
    k = Eigen::Vector2d((k.x() - pad.left) / sx, (k.y() - pad.top) / sy);
  return d;
}

namespace {

// Starts of `count` tiles of `side` spread evenly over [0, length].
std::vector<double> TileStarts(double length, double side, int count) {
  std::vector<double> starts;
  for (int i = 0; i < count; ++i) {
    starts.push_back(count == 1 ? (length - side) / 2
                                : i * (length - side) / (count - 1));
  }
  return starts;
}

// Tiles of `side` needed to cover `length` with neighbours overlapping by `overlap`.
int TilesToCover(double length, double side, double overlap) {
  if (length <= side) return 1;
  return 1 + static_cast<int>(std::ceil((length - side) / (side * (1 - overlap)) - 1e-9));
}

}  // namespace

std::vector<PalmTile> MakePalmTiles(int image_width, int image_height, int across,
                                    double overlap) {
  HL_CHECK(image_width > 0 && image_height > 0 && across >= 1,
           "palm tiles need an image and at least one tile across");
  HL_CHECK(overlap >= 0 && overlap < 1, "tile overlap must be in [0, 1)");
  const double shorter = std::min(image_width, image_height);
  const double side = shorter / (across - (across - 1) * overlap);
  const auto xs = TileStarts(image_width, side, TilesToCover(image_width, side, overlap));
  const auto ys =
      TileStarts(image_height, side, TilesToCover(image_height, side, overlap));
  std::vector<PalmTile> tiles;
  for (double y : ys) {
    for (double x : xs) tiles.push_back({x, y, side});
  }
  return tiles;
}

PalmDetection TileToImage(const PalmDetection& detection, const PalmTile& tile,
                          int image_width, int image_height) {
  const double w = image_width, h = image_height;
  const auto x = [&](double u) { return (tile.left + u * tile.side) / w; };
  const auto y = [&](double v) { return (tile.top + v * tile.side) / h; };
  PalmDetection d = detection;
  d.xmin = x(detection.xmin);
  d.ymin = y(detection.ymin);
  d.width = detection.width * tile.side / w;
  d.height = detection.height * tile.side / h;
  for (auto& k : d.keypoints) k = Eigen::Vector2d(x(k.x()), y(k.y()));
  return d;
}

void HandRoiOptions::Check(const std::string& source) const {
  const auto valid = [](int k) { return k >= 0 && k < kPalmKeypoints; };
  if (!valid(rotation_start_keypoint) || !valid(rotation_end_keypoint)) {
    throw InputError(source, "rotation keypoints", "indices in [0, 7)");
  }
  RequireGreater(source, "scale", scale, 0);
}

NormalizedRect HandRoiFromPalm(const PalmDetection& palm, int image_width,
                               int image_height, const HandRoiOptions& options) {
  options.Check("HandRoiOptions");
  const double w = image_width, h = image_height;
  const Eigen::Vector2d& p0 = palm.keypoints[options.rotation_start_keypoint];
  const Eigen::Vector2d& p1 = palm.keypoints[options.rotation_end_keypoint];
  // Angle measured in pixels with y up, so the rotation turns that direction to target.
  const double angle = std::atan2(-(p1.y() - p0.y()) * h, (p1.x() - p0.x()) * w);
  NormalizedRect roi;
  roi.rotation = NormalizeRadians(options.target_angle_deg * kPi / 180.0 - angle);
  roi.x_center = palm.xmin + palm.width / 2;
  roi.y_center = palm.ymin + palm.height / 2;
  const double c = std::cos(roi.rotation), s = std::sin(roi.rotation);
  // The shift is along the rotated box's axes, in box sizes (computed in pixels).
  const double dx_px = palm.width * w * options.shift_x,
               dy_px = palm.height * h * options.shift_y;
  roi.x_center += (c * dx_px - s * dy_px) / w;
  roi.y_center += (s * dx_px + c * dy_px) / h;
  const double long_side = std::max(palm.width * w, palm.height * h);
  roi.width = long_side / w * options.scale;
  roi.height = long_side / h * options.scale;
  return roi;
}

RotatedRect PadRoi(const RotatedRect& roi, double tensor_aspect,
                   LetterboxPadding* padding) {
  RotatedRect out = roi;
  LetterboxPadding pad;
  const double roi_aspect = roi.height / roi.width;
  if (tensor_aspect > roi_aspect) {
    out.height = roi.width * tensor_aspect;
    pad.top = pad.bottom = (1.0 - roi_aspect / tensor_aspect) / 2.0;
  } else {
    out.width = roi.height / tensor_aspect;
    pad.left = pad.right = (1.0 - tensor_aspect / roi_aspect) / 2.0;
  }
  if (padding != nullptr) *padding = pad;
  return out;
}

TensorCrop CropToTensor(const ImageU8& image, const RotatedRect& roi_in, int width,
                        int height, bool keep_aspect_ratio, BorderMode border) {
  HL_CHECK(image.channels == 3 && !image.empty(), "CropToTensor needs an RGB image");
  HL_CHECK(width > 0 && height > 0, "tensor size must be positive");
  TensorCrop crop;
  const RotatedRect roi =
      keep_aspect_ratio
          ? PadRoi(roi_in, static_cast<double>(height) / width, &crop.padding)
          : roi_in;
  crop.values.assign(static_cast<size_t>(width) * height * 3, 0.0f);
  const double c = std::cos(roi.rotation), s = std::sin(roi.rotation);
  for (int j = 0; j < height; ++j) {
    const double v = ((j + 0.5) / height - 0.5) * roi.height;
    for (int i = 0; i < width; ++i) {
      const double u = ((i + 0.5) / width - 0.5) * roi.width;
      // Continuous image coordinates (0 = left edge), as the GL texture coordinates.
      const double x = roi.x_center + c * u - s * v;
      const double y = roi.y_center + s * u + c * v;
      float* out = &crop.values[(static_cast<size_t>(j) * width + i) * 3];
      if (border == BorderMode::kZero &&
          (x < 0 || y < 0 || x > image.width || y > image.height)) {
        continue;
      }
      SampleBilinear(image, x - 0.5, y - 0.5, out);
    }
  }
  return crop;
}

Eigen::Vector2d ProjectCropPoint(const Eigen::Vector2d& crop_norm,
                                 const NormalizedRect& roi, const LetterboxPadding& pad) {
  const double x = (crop_norm.x() - pad.left) / (1.0 - pad.left - pad.right) - 0.5;
  const double y = (crop_norm.y() - pad.top) / (1.0 - pad.top - pad.bottom) - 0.5;
  const double c = std::cos(roi.rotation), s = std::sin(roi.rotation);
  return {(c * x - s * y) * roi.width + roi.x_center,
          (s * x + c * y) * roi.height + roi.y_center};
}

NormalizedRect RoiFromKeypoints(
    const Eigen::Matrix<double, 21, 2, Eigen::RowMajor>& uv_px, int image_width,
    int image_height) {
  // Continuous coordinates (pixel centres at k + 0.5), as MediaPipe's normalised ones.
  const auto at = [&](int k) {
    return Eigen::Vector2d(uv_px(k, 0) + 0.5, uv_px(k, 1) + 0.5);
  };
  const Eigen::Vector2d wrist = at(0);
  const Eigen::Vector2d top = ((at(5) + at(13)) / 2 + at(9)) / 2;
  const double rotation =
      NormalizeRadians(kPi / 2 - std::atan2(-(top.y() - wrist.y()), top.x() - wrist.x()));
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (int k : kRoiJoints) {
    lo = lo.cwiseMin(at(k));
    hi = hi.cwiseMax(at(k));
  }
  const Eigen::Vector2d axis_centre = (lo + hi) / 2;
  const double c = std::cos(rotation), s = std::sin(rotation);
  lo.setConstant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (int k : kRoiJoints) {
    const Eigen::Vector2d d = at(k) - axis_centre;
    const Eigen::Vector2d r(c * d.x() + s * d.y(),
                            -s * d.x() + c * d.y());  // by -rotation
    lo = lo.cwiseMin(r);
    hi = hi.cwiseMax(r);
  }
  const Eigen::Vector2d pc = (lo + hi) / 2;
  const Eigen::Vector2d size = hi - lo;
  // Centre back in the image, then shift 0.1 box heights towards the fingers, square on
  // the long side and scale by 2 (RectTransformation of the tracking graph).
  Eigen::Vector2d centre =
      axis_centre + Eigen::Vector2d(c * pc.x() - s * pc.y(), s * pc.x() + c * pc.y());
  const double shift = -0.1 * size.y();
  centre += Eigen::Vector2d(-s * shift, c * shift);
  const double side = 2.0 * std::max(size.x(), size.y());
  NormalizedRect roi;
  roi.x_center = centre.x() / image_width;
  roi.y_center = centre.y() / image_height;
  roi.width = side / image_width;
  roi.height = side / image_height;
  roi.rotation = rotation;
  return roi;
}

}  // namespace handlabel
