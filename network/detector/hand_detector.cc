#include "network/detector/hand_detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/stopwatch.h"
#include "geometry/triangulation.h"

namespace handlabel {
namespace {

using Points3 = std::array<Eigen::Vector3d, kPalmKeypoints>;

double PalmSizePx(const PalmDetection& p, int w, int h) {
  return std::max(p.width * w, p.height * h);
}

Eigen::Vector2d PalmKeypointPx(const PalmDetection& p, int k, int w, int h) {
  return NormToPixel(p.keypoints[k], w, h);
}

// The 7 palm keypoints triangulated from the given (view, palm) pairs.
std::optional<Points3> TriangulatePalm(
    const Rig& rig, const std::vector<ImageU8>& images,
    const std::vector<std::vector<PalmDetection>>& palms,
    const std::vector<std::pair<int, int>>& members) {
  Points3 out;
  for (int k = 0; k < kPalmKeypoints; ++k) {
    std::vector<ViewObservation> obs;
    for (const auto& [view, index] : members) {
      const ImageU8& im = images[view];
      obs.push_back(
          {view, PalmKeypointPx(palms[view][index], k, im.width, im.height), 1.0});
    }
    const auto point = TriangulateWeighted(rig, obs);
    if (!point) return std::nullopt;
    out[k] = *point;
  }
  return out;
}

// Mean distance (pixels) between a palm's keypoints and the projected 3D palm, in palm
// sizes; infinity when a point is behind the camera.
double PalmDisagreement(const RigCamera& camera, const PalmDetection& palm,
                        const Points3& p3, int w, int h) {
  double sum = 0;
  for (int k = 0; k < kPalmKeypoints; ++k) {
    Eigen::Vector2d uv;
    if (!camera.ProjectWorld(p3[k], &uv)) return std::numeric_limits<double>::infinity();
    sum += (uv - PalmKeypointPx(palm, k, w, h)).norm();
  }
  return sum / kPalmKeypoints / std::max(PalmSizePx(palm, w, h), 1.0);
}

struct PalmHypothesis {
  std::vector<std::pair<int, int>> members;  // (view, palm index)
  double score_sum = 0;
};

// Step 2: the 3D palm most views agree on.
PalmHypothesis BestPalmHypothesis(const Rig& rig, const std::vector<ImageU8>& images,
                                  const std::vector<std::vector<PalmDetection>>& palms,
                                  const MultiViewDetectorOptions& options) {
  const int n = static_cast<int>(images.size());
  PalmHypothesis best;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      for (int i = 0; i < static_cast<int>(palms[a].size()); ++i) {
        for (int j = 0; j < static_cast<int>(palms[b].size()); ++j) {
          const auto p3 = TriangulatePalm(rig, images, palms, {{a, i}, {b, j}});
          if (!p3) continue;
          PalmHypothesis h;
          for (int v = 0; v < n; ++v) {
            int best_index = -1;
            double best_d = options.palm_agreement;
            for (int c = 0; c < static_cast<int>(palms[v].size()); ++c) {
              const double d = PalmDisagreement(rig[v], palms[v][c], *p3, images[v].width,
                                                images[v].height);
              if (d < best_d) best_d = d, best_index = c;
            }
            if (best_index < 0) continue;
            h.members.push_back({v, best_index});
            h.score_sum += palms[v][best_index].score;
          }
          const bool more = h.members.size() > best.members.size();
          const bool tie_better =
              h.members.size() == best.members.size() && h.score_sum > best.score_sum;
          if (more || tie_better) best = h;
        }
      }
    }
  }
  return best;
}

// The 3D palm (7 keypoints and the box centre, triangulated from the agreeing views) and
// the box size per unit of wrist-to-middle-MCP distance, as those views saw it.
struct Palm3d {
  Points3 keypoints;
  Eigen::Vector3d box_centre = Eigen::Vector3d::Zero();
  double box_per_span = 0;
};

std::optional<Palm3d> TriangulatePalmWithBox(
    const Rig& rig, const std::vector<ImageU8>& images,
    const std::vector<std::vector<PalmDetection>>& palms, const PalmHypothesis& h) {
  const auto keypoints = TriangulatePalm(rig, images, palms, h.members);
  if (!keypoints) return std::nullopt;
  Palm3d out;
  out.keypoints = *keypoints;
  std::vector<ViewObservation> centres;
  for (const auto& [v, index] : h.members) {
    const PalmDetection& p = palms[v][index];
    const int w = images[v].width, ht = images[v].height;
    centres.push_back(
        {v, NormToPixel({p.xmin + p.width / 2, p.ymin + p.height / 2}, w, ht), 1.0});
    const double span =
        (PalmKeypointPx(p, 2, w, ht) - PalmKeypointPx(p, 0, w, ht)).norm();
    out.box_per_span += PalmSizePx(p, w, ht) / std::max(span, 1.0) / h.members.size();
  }
  const auto centre = TriangulateWeighted(rig, centres);
  if (!centre) return std::nullopt;
  out.box_centre = *centre;
  return out;
}

// The 3D palm seen from camera `camera` as a palm detection (normalised), a square box of
// the agreeing views' size per span; nothing when it projects behind the camera or
// its centre falls outside the image.
std::optional<PalmDetection> ProjectPalm(const RigCamera& camera, const Palm3d& palm,
                                         int w, int h) {
  PalmDetection out;
  out.score = 0;
  std::array<Eigen::Vector2d, kPalmKeypoints> px;
  for (int k = 0; k < kPalmKeypoints; ++k) {
    if (!camera.ProjectWorld(palm.keypoints[k], &px[k])) return std::nullopt;
    out.keypoints[k] = Eigen::Vector2d((px[k].x() + 0.5) / w, (px[k].y() + 0.5) / h);
  }
  Eigen::Vector2d centre;
  if (!camera.ProjectWorld(palm.box_centre, &centre) || !camera.camera.InImage(centre)) {
    return std::nullopt;
  }
  const double size = palm.box_per_span * (px[2] - px[0]).norm();
  out.xmin = (centre.x() + 0.5 - size / 2) / w;
  out.ymin = (centre.y() + 0.5 - size / 2) / h;
  out.width = size / w;
  out.height = size / h;
  return out;
}

double MedianReprojectionPx(const RigCamera& camera, const Keypoints2d& kp,
                            const FrameHandResult& frame) {
  std::vector<double> errors;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (!frame.keypoint3d_valid[k] || kp.confidence(k) <= 0) continue;
    Eigen::Vector2d uv;
    if (!camera.ProjectWorld(frame.keypoints3d.row(k).transpose(), &uv)) continue;
    errors.push_back((uv - kp.uv_px.row(k).transpose()).norm());
  }
  if (errors.empty()) return -1;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

double RoiSizePx(const NormalizedRect& roi, int w, int h) {
  return std::sqrt(roi.width * w * roi.height * h);
}

// Step 4: robust per-keypoint triangulation from the detected views.
void TriangulateKeypoints(const Rig& rig, const std::vector<ImageU8>& images,
                          const MultiViewDetectorOptions& options,
                          FrameHandResult* frame) {
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    std::vector<ViewObservation> obs;
    double roi_px = 0;
    for (int v = 0; v < static_cast<int>(frame->views.size()); ++v) {
      const ViewHandResult& r = frame->views[v];
      if (!r.detected || r.keypoints.confidence(k) <= 0) continue;
      obs.push_back({v, r.keypoints.uv_px.row(k).transpose(), r.keypoints.confidence(k)});
      roi_px = std::max(roi_px, RoiSizePx(r.hand.roi, images[v].width, images[v].height));
    }
    RobustTriangulationOptions ro;
    ro.inlier_threshold_px = std::max(2.0, options.keypoint_inlier * roi_px);
    const RobustTriangulation t = TriangulateRobust(rig, obs, ro);
    frame->keypoint3d_valid[k] = t.valid;
    if (t.valid) frame->keypoints3d.row(k) = t.point.transpose();
  }
}

// The 3D hand projected into view v; false when too little of it lands in the image.
bool ProjectHand(const RigCamera& camera, const FrameHandResult& frame,
                 const MultiViewDetectorOptions& options, KeypointPixels* uv_px) {
  int inside = 0, valid = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (!frame.keypoint3d_valid[k]) continue;
    Eigen::Vector2d uv;
    if (!camera.ProjectWorld(frame.keypoints3d.row(k).transpose(), &uv)) return false;
    uv_px->row(k) = uv.transpose();
    ++valid;
    if (camera.camera.InImage(uv)) ++inside;
  }
  if (valid < kNumHandKeypoints) {
    // Missing 3D keypoints: the ROI rule needs them all; use the projected wrist for
    // the missing ones only when the wrist exists.
    if (!frame.keypoint3d_valid[0]) return false;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!frame.keypoint3d_valid[k]) uv_px->row(k) = uv_px->row(0);
    }
  }
  return inside >= options.min_keypoints_in_view * kNumHandKeypoints;
}

// `min_presence`: the detector's own threshold for ROIs from the view's palm, the lower
// `min_presence_from_3d` for ROIs the other views put there.
void RunLandmarks(const MediapipeHands& detector, const ImageU8& image,
                  const NormalizedRect& roi, const std::string& source,
                  double min_presence, ViewHandResult* r) {
  const auto start = std::chrono::steady_clock::now();
  r->hand = detector.LandmarksInRoi(image, roi);
  r->landmarks_seconds += SecondsSince(start);
  r->detected = r->hand.presence >= min_presence;
  if (r->detected) {
    r->source = source;
    r->reason.clear();
    r->keypoints = r->hand.ToKeypoints(image.width, image.height);
  } else {
    r->source.clear();
    r->reason = "low_presence";
    r->keypoints = Keypoints2d();
  }
}

// Step 5: drop views that disagree with the triangulated hand.
void DropInconsistentViews(const Rig& rig, const std::vector<ImageU8>& images,
                           const MultiViewDetectorOptions& options,
                           FrameHandResult* frame) {
  for (int v = 0; v < static_cast<int>(frame->views.size()); ++v) {
    ViewHandResult& r = frame->views[v];
    if (!r.detected) continue;
    r.median_reprojection_px = MedianReprojectionPx(rig[v], r.keypoints, *frame);
    const double limit = options.max_reprojection *
                         RoiSizePx(r.hand.roi, images[v].width, images[v].height);
    if (r.median_reprojection_px > limit) {
      r.detected = false;
      r.reason = "inconsistent_with_3d_hand";
      r.source.clear();
      r.keypoints = Keypoints2d();
    }
  }
}

// Video mode, first pass: landmarks in every view on the ROI of the previous frame's 3D
// hand (views in parallel: each writes its own result). Such a ROI is placed from 3D,
// so its landmarks count from min_presence_from_3d, as 3d_palm and 3d_hand ROIs do.
// Returns the views where the track holds (presence >= the detector's min_presence).
int TrackViews(const MediapipeHands& detector, const Rig& rig,
               const std::vector<ImageU8>& images, const FrameHandResult& previous,
               const MultiViewDetectorOptions& options, FrameHandResult* frame) {
  tbb::parallel_for(0, static_cast<int>(images.size()), [&](int v) {
    ViewHandResult& r = frame->views[v];
    const std::optional<NormalizedRect> roi =
        RoiOfTrackedHand(rig[v], previous, options, images[v].width, images[v].height);
    if (!roi) {
      r.region = "outside";
      r.reason = "hand_outside_view";
      return;
    }
    r.region = "track";
    RunLandmarks(detector, images[v], *roi, "track", options.min_presence_from_3d, &r);
  });
  int held = 0;
  for (const ViewHandResult& r : frame->views) {
    held += r.region == "track" && r.hand.presence >= detector.options().min_presence;
  }
  return held;
}

// Video mode: palm detection in a view where the track did not hold. The palm whose box
// centre lies inside the tracked ROI (the nearest to its centre) gives landmarks; they
// replace the tracked ones when they pass the detector's min_presence and are more
// present (a palm elsewhere in the view is another hand or a false palm).
void RedetectLostView(const MediapipeHands& detector, const ImageU8& image,
                      ViewHandResult* r) {
  r->region = "palm";
  const auto palm_start = std::chrono::steady_clock::now();
  r->palms = detector.DetectPalms(image);
  r->palm_seconds += SecondsSince(palm_start);
  r->palm_candidates = static_cast<int>(r->palms.size());
  const RotatedRect track = r->hand.roi.ToPixels(image.width, image.height);
  const PalmDetection* nearest = nullptr;
  double nearest_px = std::min(track.width, track.height) / 2;
  for (const PalmDetection& palm : r->palms) {
    const Eigen::Vector2d centre((palm.xmin + palm.width / 2) * image.width,
                                 (palm.ymin + palm.height / 2) * image.height);
    const double d = (centre - Eigen::Vector2d(track.x_center, track.y_center)).norm();
    if (d < nearest_px) nearest_px = d, nearest = &palm;
  }
  if (!nearest) return;
  const auto landmarks_start = std::chrono::steady_clock::now();
  const HandLandmarks from_palm = detector.LandmarksInRoi(
      image, HandRoiFromPalm(*nearest, image.width, image.height));
  r->landmarks_seconds += SecondsSince(landmarks_start);
  if (from_palm.presence < detector.options().min_presence ||
      from_palm.presence <= r->hand.presence) {
    return;
  }
  r->hand = from_palm;
  r->detected = true;
  r->source = "palm";
  r->reason.clear();
  r->keypoints = r->hand.ToKeypoints(image.width, image.height);
}

void VoteSide(FrameHandResult* frame) {
  double weight = 0, right = 0;
  for (const ViewHandResult& r : frame->views) {
    if (!r.detected) continue;
    // left_in_mirror_score is the probability of the person's right hand.
    right += r.hand.presence * r.hand.left_in_mirror_score;
    weight += r.hand.presence;
  }
  if (weight <= 0) return;
  const double p_right = right / weight;
  frame->side = p_right >= 0.5 ? HandSide::kRight : HandSide::kLeft;
  frame->side_score = p_right >= 0.5 ? p_right : 1 - p_right;
}

// Step 1: every view's palms (into `palms`, rig order), and the frame as it is when
// no palms agree: per view the palms found and the reason "no_hand_in_frame".
FrameHandResult DetectPalmsInViews(const MediapipeHands& detector,
                                   const std::vector<ImageU8>& images,
                                   std::vector<std::vector<PalmDetection>>* palms) {
  const int n = static_cast<int>(images.size());
  FrameHandResult frame;
  frame.views.resize(n);
  palms->assign(n, {});
  for (int v = 0; v < n; ++v) {
    const auto start = std::chrono::steady_clock::now();
    (*palms)[v] = detector.DetectPalms(images[v]);
    frame.views[v].palm_seconds = SecondsSince(start);
    frame.views[v].palm_candidates = static_cast<int>((*palms)[v].size());
    frame.views[v].palms = (*palms)[v];
    frame.views[v].reason = "no_hand_in_frame";
  }
  return frame;
}

// Steps 3 and 4a: landmarks where the palms of `best` agreed, then in the views whose
// palm detection missed, from the projected 3D palm.
void LandmarksFromPalms(const MediapipeHands& detector, const Rig& rig,
                        const std::vector<ImageU8>& images,
                        const std::vector<std::vector<PalmDetection>>& palms,
                        const PalmHypothesis& best,
                        const MultiViewDetectorOptions& options, FrameHandResult* frame) {
  for (const auto& [v, index] : best.members) {
    const NormalizedRect roi =
        HandRoiFromPalm(palms[v][index], images[v].width, images[v].height);
    RunLandmarks(detector, images[v], roi, "palm", detector.options().min_presence,
                 &frame->views[v]);
  }
  const auto palm3d = TriangulatePalmWithBox(rig, images, palms, best);
  for (int v = 0; v < static_cast<int>(images.size()) && palm3d; ++v) {
    ViewHandResult& r = frame->views[v];
    if (r.detected || r.reason == "low_presence") continue;
    const auto palm = ProjectPalm(rig[v], *palm3d, images[v].width, images[v].height);
    if (!palm) {
      r.reason = "hand_outside_view";
      continue;
    }
    RunLandmarks(detector, images[v],
                 HandRoiFromPalm(*palm, images[v].width, images[v].height), "3d_palm",
                 options.min_presence_from_3d, &r);
  }
}

// Fewer than two views agree on the keypoints: no view's hand can be checked against
// the others (step 5), and one view alone leaves its depth unknown (a fit from it lands
// metres off). Dropped, with the reason.
void DropUnconfirmedViews(FrameHandResult* frame) {
  for (ViewHandResult& r : frame->views) {
    if (!r.detected) continue;
    r.detected = false;
    r.reason = "unconfirmed_by_other_views";
    r.source.clear();
    r.keypoints = Keypoints2d();
  }
}

// Step 4b: views still without a hand from the projected 3D keypoints (all views in a
// second pass), each time re-triangulated.
void LandmarksFromKeypoints(const MediapipeHands& detector, const Rig& rig,
                            const std::vector<ImageU8>& images,
                            const MultiViewDetectorOptions& options,
                            FrameHandResult* frame) {
  const int n = static_cast<int>(images.size());
  const auto redo_from_3d = [&](int v, const std::string& source) {
    KeypointPixels uv = KeypointPixels::Zero();
    if (!ProjectHand(rig[v], *frame, options, &uv)) {
      frame->views[v].detected = false;
      frame->views[v].reason = "hand_outside_view";
      return;
    }
    RunLandmarks(detector, images[v],
                 RoiFromKeypoints(uv, images[v].width, images[v].height), source,
                 options.min_presence_from_3d, &frame->views[v]);
  };
  for (int v = 0; v < n; ++v) {
    if (!frame->views[v].detected && frame->views[v].reason != "hand_outside_view") {
      redo_from_3d(v, "3d_hand");
    }
  }
  TriangulateKeypoints(rig, images, options, frame);
  if (options.second_pass) {
    for (int v = 0; v < n; ++v) redo_from_3d(v, "second_pass");
    TriangulateKeypoints(rig, images, options, frame);
  }
}

// Steps 3-5 for the palms of `best` (indices into `palms`): `frame` as step 1 left it.
void HandFromHypothesis(const MediapipeHands& detector, const Rig& rig,
                        const std::vector<ImageU8>& images,
                        const std::vector<std::vector<PalmDetection>>& palms,
                        const PalmHypothesis& best,
                        const MultiViewDetectorOptions& options, FrameHandResult* frame) {
  frame->palm_views = static_cast<int>(best.members.size());
  LandmarksFromPalms(detector, rig, images, palms, best, options, frame);
  TriangulateKeypoints(rig, images, options, frame);
  frame->found = frame->keypoint3d_valid[0];
  if (!frame->found) {
    VoteSide(frame);
    DropUnconfirmedViews(frame);
    return;
  }
  LandmarksFromKeypoints(detector, rig, images, options, frame);
  DropInconsistentViews(rig, images, options, frame);
  VoteSide(frame);
}

// Step 6: whether the 3D wrist of hypothesis `h` lies within same_hand_m of the
// triangulated wrist of a hand already found (`first` or its other_hands).
bool IsKnownHand(const Rig& rig, const std::vector<ImageU8>& images,
                 const std::vector<std::vector<PalmDetection>>& palms,
                 const PalmHypothesis& h, const FrameHandResult& first,
                 const MultiViewDetectorOptions& options) {
  const auto palm3d = TriangulatePalm(rig, images, palms, h.members);
  if (!palm3d) return false;
  for (int i = 0; i <= static_cast<int>(first.other_hands.size()); ++i) {
    const FrameHandResult& hand = HandAt(first, i);
    if (!hand.keypoint3d_valid[0]) continue;
    const Eigen::Vector3d wrist = hand.keypoints3d.row(0).transpose();
    if (((*palm3d)[0] - wrist).norm() < options.same_hand_m) return true;
  }
  return false;
}

// Step 6: whether a palm lies on the hand's projection in view v: its wrist and
// middle-finger MCP (palm keypoints 0 and 2) within twice palm_agreement palm sizes of
// the hand's (keypoints 0 and 9) on average. Twice: the palm model's keypoints and the
// landmark model's are placed by two models, and differ more than two palms of one
// model do.
bool PalmOnHand(const RigCamera& camera, const PalmDetection& palm,
                const FrameHandResult& hand, const MultiViewDetectorOptions& options,
                int w, int h) {
  double sum = 0;
  const std::array<std::pair<int, int>, 2> pairs = {{{0, 0}, {2, 9}}};
  for (const auto& [palm_k, hand_k] : pairs) {
    if (!hand.keypoint3d_valid[hand_k]) return false;
    Eigen::Vector2d uv;
    if (!camera.ProjectWorld(hand.keypoints3d.row(hand_k).transpose(), &uv)) return false;
    sum += (uv - PalmKeypointPx(palm, palm_k, w, h)).norm();
  }
  return sum / 2 < 2 * options.palm_agreement * std::max(PalmSizePx(palm, w, h), 1.0);
}

// Step 6: removes from `palms` those of `h` and, when `hand` was found, every view's
// palms lying on its projection.
void SetAsidePalms(const Rig& rig, const std::vector<ImageU8>& images,
                   const FrameHandResult& hand, const PalmHypothesis& h,
                   const MultiViewDetectorOptions& options,
                   std::vector<std::vector<PalmDetection>>* palms) {
  std::vector<std::vector<bool>> claimed(palms->size());
  for (size_t v = 0; v < palms->size(); ++v) claimed[v].assign((*palms)[v].size(), false);
  for (const auto& [v, index] : h.members) claimed[v][index] = true;
  for (size_t v = 0; v < palms->size(); ++v) {
    std::vector<PalmDetection> kept;
    for (size_t i = 0; i < (*palms)[v].size(); ++i) {
      const PalmDetection& palm = (*palms)[v][i];
      const bool on_hand = hand.found && PalmOnHand(rig[v], palm, hand, options,
                                                    images[v].width, images[v].height);
      if (!claimed[v][i] && !on_hand) kept.push_back(palm);
    }
    (*palms)[v] = std::move(kept);
  }
}

// Step 6: a view's landmarks belong to one hand. A detection whose keypoints agree
// better with another hand's projection (median reprojection error) than with its own
// hand's is dropped from its hand (decided for all views first, so the order of the
// hands does not matter); a hand that lost views is re-triangulated and checked again,
// and a further hand left without a 3D hand is dropped.
void AssignSharedViews(const Rig& rig, const std::vector<ImageU8>& images,
                       const MultiViewDetectorOptions& options, FrameHandResult* first) {
  std::vector<FrameHandResult*> hands = {first};
  for (FrameHandResult& other : first->other_hands) hands.push_back(&other);
  std::vector<std::vector<int>> drop(hands.size());
  for (size_t i = 0; i < hands.size(); ++i) {
    for (int v = 0; v < static_cast<int>(images.size()); ++v) {
      const ViewHandResult& r = hands[i]->views[v];
      if (!r.detected) continue;
      for (size_t j = 0; j < hands.size(); ++j) {
        if (j == i) continue;
        const double other = MedianReprojectionPx(rig[v], r.keypoints, *hands[j]);
        const double own = r.median_reprojection_px;
        if (other >= 0 && (own < 0 || other < own)) {
          drop[i].push_back(v);
          break;
        }
      }
    }
  }
  for (size_t i = 0; i < hands.size(); ++i) {
    if (drop[i].empty()) continue;
    for (const int v : drop[i]) {
      ViewHandResult& r = hands[i]->views[v];
      r.detected = false;
      r.reason = "belongs_to_other_hand";
      r.source.clear();
      r.keypoints = Keypoints2d();
    }
    TriangulateKeypoints(rig, images, options, hands[i]);
    hands[i]->found = hands[i]->keypoint3d_valid[0];
    if (!hands[i]->found) {
      DropUnconfirmedViews(hands[i]);
      continue;
    }
    DropInconsistentViews(rig, images, options, hands[i]);
    VoteSide(hands[i]);
  }
  auto& others = first->other_hands;
  others.erase(std::remove_if(others.begin(), others.end(),
                              [](const FrameHandResult& h) { return !h.found; }),
               others.end());
}

// The frame as step 1 left it, for a further hand: its views' palm times are 0 (palm
// detection ran once, counted with the first hand).
FrameHandResult WithoutPalmTimes(FrameHandResult frame) {
  for (ViewHandResult& r : frame.views) r.palm_seconds = 0;
  return frame;
}

// Step 6: the further hands, after `first` (found from the palms of `claimed`), into
// first->other_hands. `no_hand`: the frame as step 1 left it.
void FindOtherHands(const MediapipeHands& detector, const Rig& rig,
                    const std::vector<ImageU8>& images,
                    const MultiViewDetectorOptions& options,
                    const FrameHandResult& no_hand, const PalmHypothesis& claimed,
                    std::vector<std::vector<PalmDetection>> palms,
                    FrameHandResult* first) {
  SetAsidePalms(rig, images, *first, claimed, options, &palms);
  while (1 + static_cast<int>(first->other_hands.size()) < options.max_hands) {
    const PalmHypothesis h = BestPalmHypothesis(rig, images, palms, options);
    if (static_cast<int>(h.members.size()) < options.min_palm_views) break;
    FrameHandResult hand = WithoutPalmTimes(no_hand);
    if (!IsKnownHand(rig, images, palms, h, *first, options)) {
      HandFromHypothesis(detector, rig, images, palms, h, options, &hand);
    }
    SetAsidePalms(rig, images, hand, h, options, &palms);  // h's palms at least: ends
    if (hand.found) first->other_hands.push_back(std::move(hand));
  }
  if (!first->other_hands.empty()) AssignSharedViews(rig, images, options, first);
}

}  // namespace

void MultiViewDetectorOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "min_palm_views", min_palm_views, 2);
  RequireGreater(source, "palm_agreement", palm_agreement, 0);
  RequireGreater(source, "keypoint_inlier", keypoint_inlier, 0);
  RequireGreater(source, "max_reprojection", max_reprojection, 0);
  RequireInRange(source, "min_presence_from_3d", min_presence_from_3d, 0, 1,
                 "a value in [0, 1]");
  RequireInRange(source, "min_keypoints_in_view", min_keypoints_in_view, 0, 1,
                 "a value in [0, 1]");
  RequireAtLeast(source, "max_hands", max_hands, 1);
  RequireGreater(source, "same_hand_m", same_hand_m, 0);
}

FrameHandResult DetectHandMultiView(const MediapipeHands& detector, const Rig& rig,
                                    const std::vector<ImageU8>& images,
                                    const MultiViewDetectorOptions& options) {
  options.Check("MultiViewDetectorOptions");
  HL_CHECK(images.size() == rig.size(), "one image per rig camera");
  std::vector<std::vector<PalmDetection>> palms;
  const FrameHandResult no_hand = DetectPalmsInViews(detector, images, &palms);
  FrameHandResult frame = no_hand;
  frame.max_hands = options.max_hands;
  const PalmHypothesis best = BestPalmHypothesis(rig, images, palms, options);
  if (static_cast<int>(best.members.size()) < options.min_palm_views) return frame;
  HandFromHypothesis(detector, rig, images, palms, best, options, &frame);
  if (options.max_hands > 1 && frame.found) {
    FindOtherHands(detector, rig, images, options, no_hand, best, std::move(palms),
                   &frame);
  }
  return frame;
}

int HandIndexOfSide(const FrameHandResult& frame, HandSide side) {
  for (int i = 0; i <= static_cast<int>(frame.other_hands.size()); ++i) {
    const FrameHandResult& hand = HandAt(frame, i);
    if (hand.found && hand.side == side) return i;
  }
  return frame.max_hands > 1 ? -1 : 0;
}

const FrameHandResult& HandAt(const FrameHandResult& frame, int index) {
  HL_CHECK(index >= 0 && index <= static_cast<int>(frame.other_hands.size()),
           "a hand of the frame");
  return index == 0 ? frame : frame.other_hands[index - 1];
}

std::optional<NormalizedRect> RoiOfTrackedHand(const RigCamera& camera,
                                               const FrameHandResult& previous,
                                               const MultiViewDetectorOptions& options,
                                               int image_width, int image_height) {
  KeypointPixels uv = KeypointPixels::Zero();
  if (!ProjectHand(camera, previous, options, &uv)) return std::nullopt;
  return RoiFromKeypoints(uv, image_width, image_height);
}

FrameHandResult DetectHandInVideo(const MediapipeHands& detector, const Rig& rig,
                                  const std::vector<ImageU8>& images,
                                  const FrameHandResult* previous,
                                  const MultiViewDetectorOptions& options) {
  // `given_up`: the track this frame tried first, whose model time counts too.
  const auto per_frame = [&](const char* why, const FrameHandResult* given_up = nullptr) {
    FrameHandResult frame = DetectHandMultiView(detector, rig, images, options);
    frame.tracking = why;
    for (size_t v = 0; v < frame.views.size(); ++v) {
      ViewHandResult& r = frame.views[v];
      r.region = "palm";
      if (!given_up) continue;
      r.palm_seconds += given_up->views[v].palm_seconds;
      r.landmarks_seconds += given_up->views[v].landmarks_seconds;
    }
    return frame;
  };
  if (options.max_hands > 1) {
    throw InputError("MultiViewDetectorOptions", "max_hands",
                     "1 in video mode (it tracks one hand)",
                     std::to_string(options.max_hands));
  }
  if (!previous) return per_frame("start");
  if (!previous->found) return per_frame("lost");
  options.Check("MultiViewDetectorOptions");
  HL_CHECK(images.size() == rig.size() && previous->views.size() == rig.size(),
           "one image and one previous view result per rig camera");
  FrameHandResult frame;
  frame.views.resize(images.size());
  frame.tracking = "track";
  if (TrackViews(detector, rig, images, *previous, options, &frame) <
      options.min_palm_views) {
    return per_frame("lost", &frame);
  }
  std::vector<int> lost;
  for (int v = 0; v < static_cast<int>(frame.views.size()); ++v) {
    const ViewHandResult& r = frame.views[v];
    if (r.region == "track" && r.hand.presence < detector.options().min_presence) {
      lost.push_back(v);
    }
  }
  tbb::parallel_for(size_t(0), lost.size(), [&](size_t i) {
    RedetectLostView(detector, images[lost[i]], &frame.views[lost[i]]);
  });
  TriangulateKeypoints(rig, images, options, &frame);
  frame.found = frame.keypoint3d_valid[0];
  if (!frame.found) return per_frame("lost", &frame);
  DropInconsistentViews(rig, images, options, &frame);
  VoteSide(&frame);
  return frame;
}

}  // namespace handlabel
