#include "capture/capture_look.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "capture/frame_images.h"
#include "core/errors.h"
#include "image/draw.h"
#include "image/median_image.h"

namespace handlabel {
namespace {

// SNAP keypoint order (hand/hand_model.h): the wrist and the middle finger's MCP joint,
// whose direction continues into the forearm.
constexpr int kWrist = 0;
constexpr int kMiddleMcp = 9;

// The labels' spread in the world: the hand centres' per-axis median, and the distance
// from it within which 80 % of them lie (at least 3 cm, at most 25 cm).
void Workspace(const std::vector<Points3d>& hands, Eigen::Vector3d* center,
               double* radius) {
  std::vector<Eigen::Vector3d> centres;
  for (const Points3d& k : hands) centres.push_back(k.colwise().mean());
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> v;
    for (const Eigen::Vector3d& c : centres) v.push_back(c[axis]);
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    (*center)[axis] = v[v.size() / 2];
  }
  std::vector<double> distances;
  for (const Eigen::Vector3d& c : centres) distances.push_back((c - *center).norm());
  std::sort(distances.begin(), distances.end());
  *radius = std::clamp(distances[distances.size() * 8 / 10], 0.03, 0.25);
}

}  // namespace

ImageU8 HandCoverMask(const RigCamera& camera, const Points3d& keypoints) {
  const int w = camera.camera.width(), h = camera.camera.height();
  ImageU8 cover(w, h, 3);
  std::vector<Eigen::Vector2d> uv(keypoints.rows());
  Eigen::Vector2d lo(1e30, 1e30), hi(-1e30, -1e30);
  for (int k = 0; k < keypoints.rows(); ++k) {
    const Eigen::Vector3d p = camera.cam_from_world * Eigen::Vector3d(keypoints.row(k));
    if (!camera.camera.Project(p, &uv[k])) return ImageU8(w, h, 1);  // behind: nothing
    lo = lo.cwiseMin(uv[k]);
    hi = hi.cwiseMax(uv[k]);
  }
  const double extent = (hi - lo).maxCoeff();
  if (!(extent < 4.0 * (w + h))) return ImageU8(w, h, 1);  // projected near infinity
  const Rgb on = {255, 255, 255};
  for (const Eigen::Vector2d& p : uv) DrawDisc(&cover, p, 0.35 * extent + 4, on);
  const Eigen::Vector2d arm = uv[kWrist] + 3.0 * (uv[kWrist] - uv[kMiddleMcp]);
  DrawThickLine(&cover, uv[kWrist], arm, 0.7 * extent + 8, on);
  ImageU8 mask(w, h, 1);
  for (size_t i = 0; i < mask.data.size(); ++i) mask.data[i] = cover.data[3 * i];
  return mask;
}

Rig PinholeRig(const Rig& rig) {
  Rig pinhole;
  for (const RigCamera& c : rig.cameras()) {
    RigCamera p = c;
    p.camera = Camera::Pinhole(c.camera.fx(), c.camera.fy(), c.camera.cx(), c.camera.cy(),
                               c.camera.width(), c.camera.height());
    pinhole.Add(p);
  }
  return pinhole;
}

std::vector<ImageU8> EmptySceneBackgrounds(const FrameSource& source,
                                           const std::vector<std::string>& frames,
                                           const std::vector<Points3d>& hand_keypoints,
                                           Rig* rig) {
  std::vector<std::vector<ImageU8>> images, covers;  // [camera][frame]
  for (size_t i = 0; i < frames.size(); ++i) {
    FrameInput frame = source.Load(frames[i]);
    DecodeFrameImages(&frame);
    *rig = frame.rig;
    images.resize(rig->size());
    covers.resize(rig->size());
    for (size_t c = 0; c < rig->size(); ++c) {
      if (frame.images[c].empty()) continue;  // a view without an image
      images[c].push_back(std::move(frame.images[c]));
      covers[c].push_back(HandCoverMask((*rig)[c], hand_keypoints[i]));
    }
  }
  std::vector<ImageU8> backgrounds;
  for (size_t c = 0; c < rig->size(); ++c) {
    if (images[c].empty()) {
      throw InputError(
          source.Describe(), "images of camera " + (*rig)[c].name,
          "an image in some of the frames " + frames.front() + " .. " + frames.back(),
          "none");
    }
    backgrounds.push_back(MedianImage(images[c], covers[c]));
  }
  return backgrounds;
}

Eigen::Vector3d RigUp(const Rig& rig) {
  if (rig.empty()) return Eigen::Vector3d::UnitZ();
  Eigen::Vector3d mean_view = Eigen::Vector3d::Zero();
  for (const RigCamera& c : rig.cameras()) {
    mean_view += c.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ();
  }
  mean_view /= static_cast<double>(rig.size());
  // Below a third of a unit the cameras look from all sides.
  constexpr double kMinAgreement = 0.3;
  if (mean_view.norm() < kMinAgreement) return Eigen::Vector3d::UnitZ();
  return -mean_view.normalized();
}

SynthCaptureOptions CaptureLookSynthOptions(
    const Rig& rig, const std::vector<Points3d>& hand_keypoints,
    std::shared_ptr<const std::vector<ImageU8>> photos, uint64_t seed) {
  SynthCaptureOptions o;
  o.seed = seed;
  o.view.appearance = SynthAppearance::kRealistic;
  o.view.realistic.up = RigUp(rig);
  o.view.realistic.table = false;  // the photographs show the real one
  o.view.photo_backgrounds = std::move(photos);
  o.view.depth = false;
  o.write_detections = false;
  o.scene.objects = true;
  o.scene.object_probability = 0.5;  // hands holding objects and empty hands
  Workspace(hand_keypoints, &o.scene.workspace_center, &o.scene.workspace_radius);
  return o;
}

}  // namespace handlabel
