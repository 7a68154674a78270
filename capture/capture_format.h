#pragma once
// The native capture layout (docs/capture-format.md), version 1: what `handlabel synth`
// writes and what dataset readers convert to. A capture is a folder with a manifest
// `capture.json` naming the rig file, the cameras, the frames and, per kind of file, a
// path pattern with {camera} and {frame} placeholders (relative to the folder):
//
//   capture.json                          manifest (this file's CaptureManifest)
//   rig.json                              cameras, own JSON (cameras/rig_json.h)
//   colmap/{cameras,images,points3D}.txt  the same rig as a COLMAP text model
//   images/{camera}/{frame}.png           RGB
//   masks/{camera}/{frame}.png            hand mask, 0/255 (visible hand pixels)
//   object_masks/{camera}/{frame}.png     0 = none, k = object k of the frame
//   depth/{camera}/{frame}.png            16-bit, depth_unit_m per step, 0 = none
//   keypoints/{frame}.json                ground-truth 2D keypoints per view
//   detections/{frame}.json               simulated 2D detections per view
//   detections/masks/{camera}/{frame}.png noisy hand masks
//   ground_truth/{frame}.json             hand parameters, 3D keypoints, vertices
// Kinds a capture does not have are absent from "files". This header holds the
// manifest and the per-frame records with their JSON forms; the writer is
// synth_capture.h, the reader capture_reader.h.

#include <Eigen/Core>
#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/rig.h"
#include "geometry/rigid3.h"
#include "hand/hand_lbs.h"
#include "hand/hand_model.h"
#include "hand/keypoints2d.h"

namespace handlabel {

inline constexpr int kCaptureFormatVersion = 1;
inline constexpr char kCaptureManifestFile[] = "capture.json";

// File kinds (keys of CaptureManifest::files).
inline constexpr char kFileImage[] = "image";
inline constexpr char kFileMask[] = "mask";
inline constexpr char kFileObjectMask[] = "object_mask";
inline constexpr char kFileDepth[] = "depth";
inline constexpr char kFileKeypoints[] = "keypoints";
inline constexpr char kFileDetections[] = "detections";
inline constexpr char kFileDetectionMask[] = "detection_mask";
inline constexpr char kFileGroundTruth[] = "ground_truth";

struct CaptureManifest {
  int version = kCaptureFormatVersion;
  std::string rig_file = "rig.json";         // relative to the capture folder
  std::string colmap_dir;                    // "" = no COLMAP copy of the rig
  std::vector<std::string> cameras;          // names in rig order
  std::vector<std::string> frames;           // frame ids, e.g. "000000"
  std::map<std::string, std::string> files;  // kind -> pattern
  double depth_unit_m = 1e-4;                // metres per step of 16-bit depth PNGs
  std::string world;                         // what the world frame is (free text)
  std::string hand_side = "right";           // "right" or "left"
  nlohmann::json generator = nlohmann::json::object();  // tool, seed, settings
};

nlohmann::json ManifestToJson(const CaptureManifest& manifest);
// Throws InputError naming `source` and the field.
CaptureManifest ManifestFromJson(const nlohmann::json& json, const std::string& source);

// Replaces {camera} and {frame} in `pattern` (in one pass: values are not expanded).
std::string ExpandPattern(const std::string& pattern, const std::string& camera,
                          const std::string& frame);
// A capture's camera names are folder names, values in file patterns and tokens of
// COLMAP's whitespace-separated text model, none of which can escape anything: a name
// with a space or control character, '/', '\\', '{' or '}', or "." / ".." is refused
// (InputError naming `source` and `field`). Renaming a camera (the rig file, or
// `capture import --map`) is cheap; escaped names would differ from file to file.
void CheckCameraName(const std::string& name, const std::string& source,
                     const std::string& field);
// "000042" for 42.
std::string FrameId(int index);

// The file record of one view's 2D keypoints (SNAP order). Ground truth has visibility
// (0 out of frame, 1 occluded, 2 visible; synth_view.h) and confidence 1; detections
// have confidence (0 = missing) and visibility -1. Missing positions are NaN (null in
// JSON): the record keeps what the file says, readers decide what is known.
struct ViewKeypoints {
  std::string camera;
  Keypoints2d keypoints;
  std::array<int, kNumHandKeypoints> visibility{};
  std::string status;    // ground truth: "visible", "occluded", "out_of_frame"
  int hand_pixels = -1;  // ground truth: visible hand pixels; -1 = unknown
};

// {"frame": id, "views": [...]}; `ground_truth` selects the fields written.
nlohmann::json ViewKeypointsToJson(const std::string& frame,
                                   const std::vector<ViewKeypoints>& views,
                                   bool ground_truth);
std::vector<ViewKeypoints> ViewKeypointsFromJson(const nlohmann::json& json,
                                                 const std::string& source);

// One frame's keypoint or detection file as a reader of frame `frame` of `rig` takes
// it: ViewKeypointsFromJson, then what needs the frame and the cameras, each an
// InputError naming `source` and the field: the file's "frame" (optional) must be
// `frame` (a file copied under another frame's name is not used; ids of dataset inputs,
// relative to the input folder, match when one is the other's tail after a '/':
// "0000" and "ABF1/0000"); each view's camera
// must be a camera of `rig`, once; each position given (not null) must be finite and
// within its camera's image widened by the image's size on every side (so 1e308, or a
// position in another image's pixels, is refused), except ground-truth keypoints marked
// out of frame (visibility 0: a projection near the camera plane may be anywhere).
// Returns the views in `rig` order; nullopt: no view for that camera.
std::vector<std::optional<ViewKeypoints>> FrameKeypointsFromJson(
    const nlohmann::json& json, const std::string& source, const std::string& frame,
    const Rig& rig);

// A detections file of several hands (`handlabel detect --max-hands N`, docs/detector.md:
// the first hand at the top level, as in a single-hand file, the others in
// "other_hands", each {"views", "hand"}): the hand a single-hand reader of side `side`
// takes.
struct DetectionsHandChoice {
  nlohmann::json record;  // {"frame", "views", ...}, for FrameKeypointsFromJson
  int index = 0;          // 0 = the first hand, k = other_hands[k - 1]
  int count = 1;          // hands in the file
  std::string side;       // the chosen hand's voted side; "" when the file has none
  int max_hands = 1;      // hands looked for (the file's "max_hands", 1 when absent)
  // "hand 2 of 2 (left)" for logs; "" when one hand was looked for.
  std::string Describe() const;
};
// The first hand with "found" true whose "side" is `side` (nullopt: the first hand, for
// readers that draw what the file holds, such as contact sheets), else the first (the
// hand most views confirmed) in a file of one hand looked for. In a file where several
// were ("max_hands" > 1) and none of them is of that side: InputError (the frame fails:
// another hand is not the capture's). Throws InputError naming `source` for a malformed
// "other_hands" or "max_hands".
DetectionsHandChoice ChooseDetectionsHand(const nlohmann::json& file,
                                          std::optional<HandSide> side,
                                          const std::string& source);

struct ObjectGroundTruth {
  std::string kind;  // sphere, box, cylinder
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Rigid3 world_from_object;
};

// Ground truth of one frame, all in the rig's world frame.
struct HandGroundTruth {
  std::string hand_model;  // model name
  std::string side = "right";
  std::string pose_kind;
  HandParams params;
  Points3d keypoints;  // 21 x 3, SNAP order
  Points3d joints;     // 16 x 3, native order
  Points3d vertices;   // V x 3
  std::vector<ObjectGroundTruth> objects;
};

nlohmann::json GroundTruthToJson(const std::string& frame, const HandGroundTruth& gt);
HandGroundTruth GroundTruthFromJson(const nlohmann::json& json,
                                    const std::string& source);

}  // namespace handlabel
