#pragma once
// Renders one camera's view of a synthetic scene with exact ground truth: RGB over a
// procedural background, the hand mask (visible hand pixels), the object label mask,
// depth, and the 21 keypoints projected with their visibility.
//
// Keypoint visibility (COCO-like codes):
//   0 kOutOfFrame  the projection falls outside the image (or behind the camera)
//   1 kOccluded    inside the image, but an object (or scenery: the realistic look's
//                  forearm or table) is nearer at that pixel, or the hand
//                  surface there is more than `self_occlusion_tolerance` in front of
//                  the keypoint (joints lie inside the finger, so a small margin is
//                  normal)
//   2 kVisible     otherwise
// `behind_object` marks the occluded keypoints that an object hides (an object, not the
// hand, is nearest at the keypoint's pixel): simulated detections treat them apart
// (capture/synth_detections.h).
// View status: "visible" (some hand pixel is visible), "occluded" (the hand projects
// into the image but no hand pixel is visible), "out_of_frame" (no hand pixel and no
// keypoint inside the image).

#include <Eigen/Core>
#include <array>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "capture/synth_appearance.h"
#include "capture/synth_background.h"
#include "capture/synth_scene.h"
#include "geometry/rig.h"
#include "image/image.h"
#include "image/rasterizer.h"

namespace handlabel {

enum KeypointVisibility : int { kOutOfFrame = 0, kOccluded = 1, kVisible = 2 };

struct SynthViewOptions {
  BackgroundOptions background;
  // Metres the hand surface may lie in front of a keypoint before it counts as
  // self-occluded (> 0).
  double self_occlusion_tolerance = 0.025;
  // Whether to keep the depth image in the result.
  bool depth = true;
  // The look (capture/synth_appearance.h): kRealistic draws a wall instead of the
  // procedural background and adds the camera's blur and noise; the scene's scenery is
  // drawn in both.
  SynthAppearance appearance = SynthAppearance::kBasic;
  RealisticLookOptions realistic;
  // Photographs of the scene without the hand, one per rig camera (rig order), each of
  // its camera's size: drawn behind the render instead of the wall or the procedural
  // background, so the hand appears in the user's own scene (image/median_image.h
  // makes them from a recording). Empty: none. SynthGenerator checks the count and
  // sizes, and leaves the realistic look's table out (the photographs have the real one);
  // the look's camera blur and noise then touch the rendered pixels and their edges only
  // (the photographs have their own).
  std::shared_ptr<const std::vector<ImageU8>> photo_backgrounds;
  void Check(const std::string& source) const;
};

struct SynthView {
  ImageU8 rgb;          // 3 channels
  ImageU8 hand_mask;    // 255 = visible hand pixel
  ImageU8 object_mask;  // 0 = none, k = scene.objects[k - 1]
  ImageF depth;         // camera z in metres, 0 where nothing was drawn (if requested)
  Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor> keypoints;  // pixels
  std::array<int, kNumHandKeypoints> visibility{};
  std::array<bool, kNumHandKeypoints> behind_object{};  // hidden by an object
  int hand_pixels = 0;                                  // visible hand pixels
  int hand_pixels_unoccluded = 0;  // hand pixels if there were no objects
  std::string status;              // "visible", "occluded" or "out_of_frame"
};

// `rays` must belong to `camera.camera`. The background is `photo_background` when
// given (the camera's size), else drawn from `background_rng`.
SynthView RenderSynthView(const SynthScene& scene, const RigCamera& camera,
                          const PixelRays& rays, const SynthViewOptions& options,
                          std::mt19937_64& background_rng,
                          const ImageU8* photo_background = nullptr);

}  // namespace handlabel
