#pragma once
// MediaPipe Hands in C++: palm detection, the rotated hand ROI from a palm, and hand
// landmarks + presence + handedness on the ROI crop, as the @mediapipe/hands graphs run
// them on one image (static-image mode: every image starts with palm detection), on the
// package's own TFLite models run by network/detector/tflite_model.h. Torch-free.
//
// Distortion: the models run on the image as it is (distorted), as MediaPipe does, so all
// pixel positions here are distorted full-image pixels, the coordinates of a capture's
// keypoints and detections files; callers that need rays undistort through the rig
// camera.
//
// Per-keypoint confidence (Keypoints2d::confidence): the landmark model gives one hand
// presence score and no per-keypoint score, so a keypoint's confidence is the hand's
// presence score when it lies inside the image (pixel centre within [-0.5, size - 0.5])
// and 0 outside (the model guesses such points from the hand's shape; nothing in the view
// supports them).

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "hand/hand_model.h"
#include "hand/keypoints2d.h"
#include "image/image.h"
#include "network/detector/mediapipe_geometry.h"

namespace handlabel {

class TfliteModel;

// MediapipeHandsOptions::palm_tiles: tiles chosen from the image size.
inline constexpr int kPalmTilesAuto = -1;

struct MediapipeHandsOptions {
  // "full" or "lite": which pair of models (palm detection + hand landmark).
  std::string model = "full";
  // Folder with palm_detection_{full,lite}.tflite and hand_landmark_{full,lite}.tflite;
  // empty = <data folder>/models/mediapipe (scripts/fetch-mediapipe-models fills it).
  std::string model_dir;
  // Palms scoring below this are dropped (MediaPipe's min_detection_confidence).
  double min_palm_score = 0.5;
  // IoU above which weighted NMS merges palm boxes (palm_detection graph: 0.3).
  double nms_iou = 0.3;
  // A hand is reported when its presence score is >= this (min_tracking_confidence).
  double min_presence = 0.5;
  // At most this many palms (the best) go on to landmarks (MediaPipe's maxNumHands).
  int max_hands = 2;
  // Palm detection also over overlapping square tiles, for hands too small for the
  // whole image letterboxed into 192x192 (a 40 px hand of a 1920x1080 view is 4 px
  // there). N >= 1: N tiles across the image's shorter side (and as many as it takes
  // along the longer one, neighbours overlapping by a quarter tile), each tile's palms
  // mapped to the image and merged with the whole image's by weighted NMS; 0: the
  // whole image only (MediaPipe's own pipeline); kPalmTilesAuto: the whole image only
  // up to 1280 px on the longer side (table-top rigs: as before), 4 tiles across above
  // (PalmTilesAcross). Text form: "auto", "off" or N (ParsePalmTiles).
  int palm_tiles = kPalmTilesAuto;
  // LibTorch threads of each model call (set for the calling thread only); 0 = the
  // calling thread's setting. 1 by default: callers run frames or views in parallel
  // instead. The models are small, so most of a call split over threads is spent
  // waiting at OpenMP's barriers, and with another process on a core that waiting takes
  // over (docs/speed.md, "Threads under load").
  int num_threads = 1;
  // Throws InputError naming `source` when a field is out of range.
  void Check(const std::string& source) const;
};

// The landmark model's answer on one ROI.
struct HandLandmarks {
  NormalizedRect roi;  // the ROI it ran on (normalised to the image)
  // 21 landmarks, SNAP order (MediaPipe's order is the same): x, y normalised to the
  // image, z MediaPipe's relative depth (scaled like x).
  std::array<Eigen::Vector3d, kNumHandKeypoints> normalized{};
  // The same in full-image pixels (handlabel convention) and in the 224x224 crop's
  // pixels.
  KeypointPixels image_px = KeypointPixels::Zero();
  KeypointPixels crop_px = KeypointPixels::Zero();
  // World landmarks in metres, rotated back by the ROI rotation (MediaPipe's).
  std::array<Eigen::Vector3d, kNumHandKeypoints> world_m{};
  // Hand presence score in [0, 1].
  double presence = 0;
  // The model's handedness score: probability that the hand is a left hand in a mirrored
  // (selfie) image, i.e. MediaPipe's label "Left"; on an ordinary photo it is the
  // probability of the person's RIGHT hand.
  double left_in_mirror_score = 0;
  // The person's side in an unmirrored image, and the probability of that side.
  HandSide side() const {
    return left_in_mirror_score >= 0.5 ? HandSide::kRight : HandSide::kLeft;
  }
  double side_score() const {
    return left_in_mirror_score >= 0.5 ? left_in_mirror_score
                                       : 1.0 - left_in_mirror_score;
  }
  // Keypoints with the per-keypoint confidence rule of this header.
  Keypoints2d ToKeypoints(int image_width, int image_height) const;
};

// One hand found in an image: the palm that started it and its landmarks.
struct HandDetection {
  PalmDetection palm;  // normalised to the image
  HandLandmarks hand;
  Keypoints2d keypoints;  // distorted full-image pixels with confidences
};

// What Detect saw on the way: every palm after NMS (before max_hands) and step times.
struct MediapipeTrace {
  std::vector<PalmDetection> palms;
  double palm_ms = 0;       // crop + palm model + decoding + NMS
  double landmarks_ms = 0;  // all ROIs: crop + landmark model + projection
};

class MediapipeHands {
 public:
  // Loads both models; throws InputError naming the file when one is missing or bad.
  explicit MediapipeHands(const MediapipeHandsOptions& options = {});
  ~MediapipeHands();
  MediapipeHands(const MediapipeHands&) = delete;
  MediapipeHands& operator=(const MediapipeHands&) = delete;

  const MediapipeHandsOptions& options() const { return options_; }

  // All three take RGB images (3 channels) and throw InputError otherwise.
  // Palm detection on the whole image (letterboxed to 192x192) and on the tiles of
  // options().palm_tiles: every palm after NMS, normalised to the image, best first.
  std::vector<PalmDetection> DetectPalms(const ImageU8& rgb) const;
  // Landmarks in one ROI (normalised to the image; square in pixels for an undistorted
  // crop), whatever the presence score.
  HandLandmarks LandmarksInRoi(const ImageU8& rgb, const NormalizedRect& roi) const;
  // The single-image pipeline: palms, the best max_hands of them, their ROIs, landmarks;
  // hands with presence >= min_presence, in palm order. `trace` (optional) receives the
  // palms and step times.
  std::vector<HandDetection> Detect(const ImageU8& rgb,
                                    MediapipeTrace* trace = nullptr) const;

 private:
  MediapipeHandsOptions options_;
  // Palms in one square-ish region of the image (the whole image, letterboxed, or a
  // tile), after NMS, normalised to that region.
  std::vector<PalmDetection> PalmsInRegion(const ImageU8& rgb,
                                           const RotatedRect& region) const;

  std::unique_ptr<TfliteModel> palm_model_;
  std::unique_ptr<TfliteModel> landmark_model_;
  std::vector<Eigen::Vector2d> anchors_;
};

// Tiles across the shorter side that palm detection uses on an image of this size: the
// option's N, 0 for off, and for auto the rule of the .cc (measured in
// docs/detector.md, "Small hands").
int PalmTilesAcross(const MediapipeHandsOptions& options, int image_width,
                    int image_height);

// "auto" -> kPalmTilesAuto, "off" -> 0, "N" (1..16) -> N; anything else throws
// InputError(source, field, ...). PalmTilesText is the inverse.
int ParsePalmTiles(const std::string& text, const std::string& source,
                   const std::string& field);
std::string PalmTilesText(int palm_tiles);

// <model_dir or data folder>/models/mediapipe/<kind>_<model>.tflite, kind =
// palm_detection or hand_landmark.
std::string MediapipeModelPath(const MediapipeHandsOptions& options,
                               const std::string& kind);

}  // namespace handlabel
