#pragma once
// Multi-view hand finding with MediaPipe Hands (network/detector/mediapipe_hands.h): one
// hand per frame, found consistently across a calibrated rig.
//
//  1. Palm candidates in every view (palm detection on the whole image).
//  2. Every pair of candidates from two views is triangulated (the 7 palm keypoints);
//     the hypothesis that the most other views confirm (a candidate whose keypoints lie
//     within `palm_agreement` palm sizes of the projection) wins, and is re-triangulated
//     from all its views. Two views can agree on two different hands; a third one rarely
//     does, so ties go to more views, then to the higher summed palm score.
//  3. Landmarks in the confirming views (ROI from their palm); handedness is voted:
//     presence-weighted mean of the per-view probabilities.
//  4. Where palm detection missed the hand, the 3D palm (its keypoints and box centre,
//     triangulated from those views; box size from their box-to-palm-span ratio) is
//     projected and its ROI cropped for the landmark model. Then the 21 keypoints are
//     triangulated (robustly, per keypoint) from every view with landmarks, and views
//     still without a hand get the ROI around the projected keypoints. Optionally
//     (`second_pass`) every view is redone from the keypoints triangulated from all.
//  5. A view's detection that disagrees with the triangulated hand (median reprojection
//     error above `max_reprojection` ROI sizes) is dropped.
//  6. With max_hands > 1: the palms that confirmed the hand and every view's palms lying
//     on its projection are set aside, and steps 2-5 repeat on the remaining palms, up
//     to max_hands hands; a hypothesis whose 3D wrist lies within same_hand_m of an
//     earlier hand's is that hand again (dropped). Then a view's landmarks belong to
//     one hand: a detection that agrees better with another hand's projection than with
//     its own hand's is dropped from its hand ("belongs_to_other_hand").
// Each view without a detection records why (ViewHandResult::reason).
//
// Pixels are distorted image pixels (the models run on the images as they are);
// triangulation undistorts through the rig's camera models (geometry/triangulation.h).

#include <optional>
#include <string>
#include <vector>

#include "geometry/rig.h"
#include "hand/hand_model.h"
#include "hand/keypoints2d.h"
#include "image/image.h"
#include "network/detector/mediapipe_hands.h"

namespace handlabel {

struct MultiViewDetectorOptions {
  // Fewest views whose palms must agree on a 3D palm.
  int min_palm_views = 2;
  // A candidate palm confirms a 3D palm when its keypoints' mean distance to the
  // projection is below this many palm sizes (longer side of its box, pixels).
  double palm_agreement = 0.25;
  // Keypoint triangulation: inlier threshold as a share of the view's ROI size.
  double keypoint_inlier = 0.05;
  // A view's detection is dropped when its median keypoint reprojection error exceeds
  // this share of its ROI size.
  double max_reprojection = 0.1;
  // A projected hand is looked for in a view only when at least this share of its 21
  // keypoints projects inside the image.
  double min_keypoints_in_view = 0.5;
  // Presence a hand needs in a ROI placed from the other views (3D palm or keypoints):
  // there the rig already says where the hand is, and held objects hide much of it, so
  // this is below the single-image threshold (MediapipeHandsOptions::min_presence); the
  // reprojection check (max_reprojection) still drops crops that disagree.
  double min_presence_from_3d = 0.2;
  // Redo every view from the ROI of the keypoints triangulated from all views.
  bool second_pass = false;
  // Hands looked for per frame (step 6); 1 = the one most views confirm.
  int max_hands = 1;
  // Step 6: a further palm hypothesis whose 3D wrist lies within this distance (metres)
  // of an earlier hand's triangulated wrist is that hand again.
  double same_hand_m = 0.04;
  // Throws InputError naming `source` when a field is out of range.
  void Check(const std::string& source) const;
};

// One view's outcome.
struct ViewHandResult {
  bool detected = false;
  // "palm" (ROI from this view's palm), "3d_palm" (from the projected 3D palm),
  // "3d_hand" (from the projected 3D keypoints), "second_pass", or in video mode
  // "track" (from the previous frame's 3D hand); empty without one.
  std::string source;
  // Video mode only (empty otherwise): which regions the view looked at. "palm": palm
  // detection ran on the view (then as in per-frame mode); "track": only the ROI of the
  // previous frame's 3D hand; "outside": the previous frame's hand projects mostly
  // outside the view, nothing ran.
  std::string region;
  // Why there is no detection: "no_hand_in_frame" (no palms agreed in enough views),
  // "hand_outside_view" (the 3D hand projects mostly outside the image or behind the
  // camera), "low_presence" (the landmark model found no hand in the ROI),
  // "inconsistent_with_3d_hand" (its keypoints disagree with the triangulated hand),
  // "unconfirmed_by_other_views" (a hand in this view, but in no other: no 3D hand to
  // check it against, and one view leaves its depth unknown), "belongs_to_other_hand"
  // (max_hands > 1: its keypoints agree better with another hand found in the frame).
  std::string reason;
  int palm_candidates = 0;           // palms the view's palm detection found
  std::vector<PalmDetection> palms;  // those palms (normalised to the image), best first
  HandLandmarks hand;                // valid when detected
  Keypoints2d keypoints;  // distorted pixels, confidence per header rule; 0 = missing
  double median_reprojection_px = -1;  // against the triangulated keypoints; -1 unknown
  // Wall seconds this view's palm detection and landmark model calls took (every pass,
  // in video mode also a track given up for per-frame detection), for the label job's
  // stage times; not written into detections files.
  double palm_seconds = 0;
  double landmarks_seconds = 0;
};

struct FrameHandResult {
  std::vector<ViewHandResult> views;  // rig order
  bool found = false;                 // a 3D hand was established
  HandSide side = HandSide::kRight;   // voted (person's side)
  double side_score = 0;              // voted probability of `side`
  int palm_views = 0;                 // views whose palms agreed
  // Triangulated keypoints (world frame) and whether each one is valid.
  Eigen::Matrix<double, kNumHandKeypoints, 3, Eigen::RowMajor> keypoints3d =
      Eigen::Matrix<double, kNumHandKeypoints, 3, Eigen::RowMajor>::Zero();
  std::array<bool, kNumHandKeypoints> keypoint3d_valid{};
  // Video mode only (empty otherwise): "start" (a run's first frame: palm detection on
  // every view, as per-frame mode), "lost" (the previous frame had no hand, or fewer
  // than min_palm_views views held the track: detected as per-frame mode), "track"
  // (regions from the previous frame's 3D hand).
  std::string tracking;
  // max_hands > 1: the frame's further hands, in the order found (each with its own
  // views, keypoints, side; their views' palm_seconds are 0: palm detection ran once, for
  // this first hand). Empty with max_hands 1, and in every element of the list.
  std::vector<FrameHandResult> other_hands;
  // Hands looked for (MultiViewDetectorOptions::max_hands; 1 in other_hands' elements):
  // with more than 1 a frame without a hand of the wanted side has none
  // (HandIndexOfSide).
  int max_hands = 1;
};

// Which hand of `frame` a single-hand job takes for a hand of side `side`: 0 = the frame
// itself, k = other_hands[k - 1]; the first found hand whose voted side is `side`. When
// there is none: -1 when several hands were looked for (frame.max_hands > 1: the hand of
// that side was not found, and another hand is not it), else 0 (the hand most views
// confirm, as the single-hand detector always gave).
int HandIndexOfSide(const FrameHandResult& frame, HandSide side);
// Hand `index` of `frame` as HandIndexOfSide counts (0 = the frame itself).
const FrameHandResult& HandAt(const FrameHandResult& frame, int index);

// Runs steps 1-6 on one frame: images[c] is the RGB image of rig camera c. The result
// is the first hand found (the one most views confirm), any further ones in
// other_hands; with max_hands 1 exactly the single-hand detector.
FrameHandResult DetectHandMultiView(const MediapipeHands& detector, const Rig& rig,
                                    const std::vector<ImageU8>& images,
                                    const MultiViewDetectorOptions& options = {});

// Video mode: the ROI of a view from the previous frame's 3D hand (`previous`'s
// triangulated keypoints projected through `camera`, a missing keypoint at the wrist's
// projection; MediaPipe's tracking rule, RoiFromKeypoints). Nothing when the previous
// frame has no wrist, a keypoint lies behind the camera or fewer than
// min_keypoints_in_view of them land in the image.
std::optional<NormalizedRect> RoiOfTrackedHand(const RigCamera& camera,
                                               const FrameHandResult& previous,
                                               const MultiViewDetectorOptions& options,
                                               int image_width, int image_height);

// Video mode: one frame of a run of consecutive frames. `previous` is the run's previous
// frame's result (nullptr on the run's first frame: then exactly DetectHandMultiView).
// When the previous frame has a 3D hand, every view's ROI is that hand's keypoints
// projected into the view (RoiFromKeypoints, MediaPipe's tracking rule) and the landmark
// model runs there, views in parallel; the track holds in a view when the presence is
// >= the detector's min_presence. Views where it does not hold run palm detection and
// take the landmarks of the palm inside the tracked ROI when they are more present;
// failing that the tracked landmarks count from min_presence_from_3d, as other ROIs
// placed from 3D do. Then triangulation and the consistency check (steps 4-5). When the
// previous frame has no hand, or fewer than min_palm_views views hold the track, or no
// 3D hand results, the frame is detected as per-frame mode ("lost"). One hand: throws
// InputError when options.max_hands > 1.
FrameHandResult DetectHandInVideo(const MediapipeHands& detector, const Rig& rig,
                                  const std::vector<ImageU8>& images,
                                  const FrameHandResult* previous,
                                  const MultiViewDetectorOptions& options = {});

}  // namespace handlabel
