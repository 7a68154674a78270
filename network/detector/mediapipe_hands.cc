#include "network/detector/mediapipe_hands.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include "core/data_dir.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/option_checks.h"
#include "formats/sha256.h"
#include "network/detector/tflite_model.h"

namespace handlabel {
namespace {

constexpr int kLandmarkValues = 3 * kNumHandKeypoints;
// palm_tiles: the most tiles across (16 across a 1080 px side are 68 px tiles).
constexpr int kMaxPalmTiles = 16;
// palm_tiles auto (PalmTilesAcross): the largest side that uses the whole image only,
// and the tiles across the shorter side of larger images.
constexpr int kAutoWholeImageOnlyPx = 1280;
constexpr int kAutoPalmTiles = 4;
// TensorsToLandmarksCalculator's normalize_z for the hand landmark model.
constexpr double kLandmarkZScale = 0.4;

void CheckShape(const TfliteTensorInfo& info, const std::vector<int>& want,
                const std::string& path, const std::string& what) {
  if (info.shape == want) return;
  std::string got;
  for (int d : info.shape) got += (got.empty() ? "" : "x") + std::to_string(d);
  std::string expected;
  for (int d : want) expected += (expected.empty() ? "" : "x") + std::to_string(d);
  throw InputError(path, what + " '" + info.name + "'", "shape " + expected, got);
}

// The four files of @mediapipe/hands 0.4.1675469240 (models/NOTICE.mediapipe).
struct ShippedModel {
  const char* name;
  const char* sha256;
};
constexpr ShippedModel kShippedModels[] = {
    {"hand_landmark_full.tflite",
     "8c026882c9ec059ce0f8e75266bee5a9a23c341a40e0000df755374d3d1b9b68"},
    {"hand_landmark_lite.tflite",
     "d7fde8ac11f8ce03f8663775bfc323f4fc9f2a38062b4f4efa142874ef5b2a48"},
    {"palm_detection_full.tflite",
     "2f25e740121983f68ffc05f99991d524dc0ea812134f6316a26125816941ee85"},
    {"palm_detection_lite.tflite",
     "e9a4aaddf90dda56a87235303cf00e4c2d3fb28725f68fd88772997dac905c18"},
};

// The full and lite models have the same inputs and outputs, so a lite model copied
// under the full model's name would run without a word and give worse keypoints: a
// file holding the bytes of another shipped model than its name says is refused.
// Files of other bytes (a user's own model) are taken as named.
void RefuseAnotherShippedModel(const std::string& bytes, const std::string& path,
                               const std::string& name) {
  const std::string sha = Sha256Hex(bytes);
  for (const ShippedModel& shipped : kShippedModels) {
    if (sha != shipped.sha256 || name == shipped.name) continue;
    std::string expected = "the bytes of " + name;
    for (const ShippedModel& own : kShippedModels) {
      if (name == own.name) expected += " (sha256 " + std::string(own.sha256) + ")";
    }
    throw InputError(
        path, "content",
        expected +
            " or a model of your own (scripts/fetch-mediapipe-models "
            "fetches the shipped files)",
        "the bytes of " + std::string(shipped.name) + " (sha256 " + sha + ")");
  }
}

std::unique_ptr<TfliteModel> LoadModel(const std::string& path, const std::string& name,
                                       int num_threads) {
  const std::string bytes = ReadFileBytes(path, ".tflite file");
  RefuseAnotherShippedModel(bytes, path, name);
  TfliteModelOptions model_options;
  model_options.num_threads = num_threads;
  return TfliteModel::FromBytes(bytes, path, model_options);
}

void CheckRgb(const ImageU8& rgb) {
  if (rgb.channels != 3 || rgb.empty()) {
    throw InputError("MediapipeHands", "image", "a non-empty RGB image (3 channels)",
                     std::to_string(rgb.channels) + " channels");
  }
}

}  // namespace

void MediapipeHandsOptions::Check(const std::string& source) const {
  if (model != "full" && model != "lite") {
    throw InputError(source, "model", "full or lite", model);
  }
  RequireInRange(source, "min_palm_score", min_palm_score, 0, 1, "a value in [0, 1]");
  RequireInRange(source, "nms_iou", nms_iou, 0, 1, "a value in [0, 1]");
  RequireInRange(source, "min_presence", min_presence, 0, 1, "a value in [0, 1]");
  RequireAtLeast(source, "max_hands", max_hands, 1);
  if (palm_tiles != kPalmTilesAuto) {
    RequireInRange(source, "palm_tiles", palm_tiles, 0, kMaxPalmTiles,
                   "auto, off (0) or 1.." + std::to_string(kMaxPalmTiles));
  }
  RequireAtLeast(source, "num_threads", num_threads, 0);
}

int PalmTilesAcross(const MediapipeHandsOptions& options, int image_width,
                    int image_height) {
  if (options.palm_tiles != kPalmTilesAuto) return options.palm_tiles;
  // Up to 1280 px the whole image alone, as MediaPipe runs: the hands of table-top
  // rigs (DexYCB-, HO3D-, OakInk-like, 640-848 px wide) are 80-150 px, 25-45 px in
  // the 192x192 input, which the palm model finds; their detections stay as they were.
  if (std::max(image_width, image_height) <= kAutoWholeImageOnlyPx) return 0;
  // Larger views film more than a table top: a full-body studio's HD views show a hand
  // 30-60 px long (3-5 % of the shorter side), 3-6 px in the whole image's 192x192
  // input. Four tiles across make it 17-35 px there, about as large as table-top
  // hands in whole 640x480 images. Measured on the synthetic studio rig (docs/
  // detector.md, "Small hands"): 4 across found the hand in 95 % of the half-visible
  // views, 3 across in 75 %, 2 in 70 %, the whole image alone in none.
  return kAutoPalmTiles;
}

int ParsePalmTiles(const std::string& text, const std::string& source,
                   const std::string& field) {
  if (text == "auto") return kPalmTilesAuto;
  if (text == "off") return 0;
  const std::string expected = "auto, off or 1.." + std::to_string(kMaxPalmTiles);
  size_t used = 0;
  int n = 0;
  try {
    n = std::stoi(text, &used);
  } catch (const std::exception&) {
    throw InputError(source, field, expected, "'" + text + "'");
  }
  if (used != text.size() || n < 1 || n > kMaxPalmTiles) {
    throw InputError(source, field, expected, "'" + text + "'");
  }
  return n;
}

std::string PalmTilesText(int palm_tiles) {
  if (palm_tiles == kPalmTilesAuto) return "auto";
  if (palm_tiles == 0) return "off";
  return std::to_string(palm_tiles);
}

namespace {
std::string MediapipeModelName(const MediapipeHandsOptions& options,
                               const std::string& kind) {
  return kind + "_" + options.model + ".tflite";
}
}  // namespace

std::string MediapipeModelPath(const MediapipeHandsOptions& options,
                               const std::string& kind) {
  const std::string name = MediapipeModelName(options, kind);
  if (!options.model_dir.empty()) return options.model_dir + "/" + name;
  return ShippedModelPath("mediapipe/" + name);
}

Keypoints2d HandLandmarks::ToKeypoints(int image_width, int image_height) const {
  Keypoints2d kp;
  kp.uv_px = image_px;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const double u = image_px(k, 0), v = image_px(k, 1);
    const bool inside =
        u >= -0.5 && v >= -0.5 && u <= image_width - 0.5 && v <= image_height - 0.5;
    kp.confidence(k) = inside ? presence : 0.0;
    if (!inside) kp.uv_px.row(k).setZero();  // a missed keypoint's position says nothing
  }
  return kp;
}

MediapipeHands::MediapipeHands(const MediapipeHandsOptions& options) : options_(options) {
  options_.Check("MediapipeHandsOptions");
  const std::string palm_path = MediapipeModelPath(options_, "palm_detection");
  const std::string landmark_path = MediapipeModelPath(options_, "hand_landmark");
  palm_model_ = LoadModel(palm_path, MediapipeModelName(options_, "palm_detection"),
                          options_.num_threads);
  landmark_model_ = LoadModel(
      landmark_path, MediapipeModelName(options_, "hand_landmark"), options_.num_threads);
  anchors_ = MakeSsdAnchors();
  const int n = static_cast<int>(anchors_.size());

  const int s = kPalmModelInputSize;
  if (palm_model_->inputs().size() != 1)
    throw InputError(palm_path, "inputs", "one input");
  CheckShape(palm_model_->inputs()[0], {1, s, s, 3}, palm_path, "input");
  if (palm_model_->outputs().size() != 2)
    throw InputError(palm_path, "outputs", "two outputs");
  CheckShape(palm_model_->outputs()[0], {1, n, 18}, palm_path, "output 0 (boxes)");
  CheckShape(palm_model_->outputs()[1], {1, n, 1}, palm_path, "output 1 (scores)");

  const int l = kHandLandmarkInputSize;
  if (landmark_model_->inputs().size() != 1) {
    throw InputError(landmark_path, "inputs", "one input");
  }
  CheckShape(landmark_model_->inputs()[0], {1, l, l, 3}, landmark_path, "input");
  const auto& outs = landmark_model_->outputs();
  if (outs.size() != 4) throw InputError(landmark_path, "outputs", "four outputs");
  // Order as hand_landmark_gpu's SplitTensorVectorCalculator takes them.
  const int sizes[4] = {kLandmarkValues, 1, 1, kLandmarkValues};
  const char* names[4] = {"landmarks", "presence", "handedness", "world landmarks"};
  for (int i = 0; i < 4; ++i) {
    if (outs[i].num_elements() != sizes[i]) {
      throw InputError(landmark_path,
                       std::string("output ") + std::to_string(i) + " (" + names[i] + ")",
                       std::to_string(sizes[i]) + " values",
                       std::to_string(outs[i].num_elements()));
    }
  }
}

MediapipeHands::~MediapipeHands() = default;

std::vector<PalmDetection> MediapipeHands::PalmsInRegion(
    const ImageU8& rgb, const RotatedRect& region) const {
  TensorCrop crop = CropToTensor(rgb, region, kPalmModelInputSize, kPalmModelInputSize,
                                 /*keep_aspect_ratio=*/true, BorderMode::kZero);
  const auto outputs = palm_model_->Run({crop.values});
  PalmDecodeOptions decode;
  decode.min_score = options_.min_palm_score;
  auto palms = WeightedNonMaxSuppression(
      DecodePalms(outputs[0], outputs[1], anchors_, decode), options_.nms_iou);
  for (auto& p : palms) p = RemoveLetterbox(p, crop.padding);
  return palms;
}

std::vector<PalmDetection> MediapipeHands::DetectPalms(const ImageU8& rgb) const {
  CheckRgb(rgb);
  const RotatedRect whole{rgb.width / 2.0, rgb.height / 2.0,
                          static_cast<double>(rgb.width), static_cast<double>(rgb.height),
                          0.0};
  std::vector<PalmDetection> palms = PalmsInRegion(rgb, whole);
  const int across = PalmTilesAcross(options_, rgb.width, rgb.height);
  // Without tiles the whole image's palms as MediaPipe gives them (a second NMS would
  // re-average each palm with itself and move its last bits).
  if (across == 0) return palms;
  for (const PalmTile& tile : MakePalmTiles(rgb.width, rgb.height, across)) {
    for (const PalmDetection& p : PalmsInRegion(rgb, tile.ToRect())) {
      palms.push_back(TileToImage(p, tile, rgb.width, rgb.height));
    }
  }
  // A palm seen in the whole image and in overlapping tiles becomes one, as the
  // anchors that see one palm do within a region.
  return WeightedNonMaxSuppression(std::move(palms), options_.nms_iou);
}

HandLandmarks MediapipeHands::LandmarksInRoi(const ImageU8& rgb,
                                             const NormalizedRect& roi) const {
  CheckRgb(rgb);
  const int size = kHandLandmarkInputSize;
  const TensorCrop crop =
      CropToTensor(rgb, roi.ToPixels(rgb.width, rgb.height), size, size,
                   /*keep_aspect_ratio=*/true, BorderMode::kReplicate);
  const auto out = landmark_model_->Run({crop.values});
  HandLandmarks hand;
  hand.roi = roi;
  hand.presence = out[1][0];
  hand.left_in_mirror_score = out[2][0];
  const double c = std::cos(roi.rotation), s = std::sin(roi.rotation);
  const double lr = 1.0 - crop.padding.left - crop.padding.right;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const float* v = &out[0][3 * k];
    // Raw landmarks are crop pixels with pixel centres at k + 0.5.
    const Eigen::Vector2d crop_norm(v[0] / size, v[1] / size);
    hand.crop_px.row(k) = (crop_norm * size).array() - 0.5;
    const Eigen::Vector2d norm = ProjectCropPoint(crop_norm, roi, crop.padding);
    const double z = v[2] / size / kLandmarkZScale / lr * roi.width;
    hand.normalized[k] = Eigen::Vector3d(norm.x(), norm.y(), z);
    hand.image_px.row(k) = NormToPixel(norm, rgb.width, rgb.height).transpose();
    const float* w = &out[3][3 * k];
    hand.world_m[k] = Eigen::Vector3d(c * w[0] - s * w[1], s * w[0] + c * w[1], w[2]);
  }
  return hand;
}

std::vector<HandDetection> MediapipeHands::Detect(const ImageU8& rgb,
                                                  MediapipeTrace* trace) const {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<PalmDetection> palms = DetectPalms(rgb);
  const auto t1 = std::chrono::steady_clock::now();
  if (trace != nullptr) trace->palms = palms;
  if (static_cast<int>(palms.size()) > options_.max_hands)
    palms.resize(options_.max_hands);
  std::vector<HandDetection> hands;
  for (const PalmDetection& palm : palms) {
    HandDetection d;
    d.palm = palm;
    d.hand = LandmarksInRoi(rgb, HandRoiFromPalm(palm, rgb.width, rgb.height));
    if (d.hand.presence < options_.min_presence) continue;
    d.keypoints = d.hand.ToKeypoints(rgb.width, rgb.height);
    hands.push_back(d);
  }
  if (trace != nullptr) {
    const auto t2 = std::chrono::steady_clock::now();
    trace->palm_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    trace->landmarks_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  }
  return hands;
}

}  // namespace handlabel
