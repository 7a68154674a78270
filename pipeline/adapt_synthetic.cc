#include "pipeline/adapt_run.h"

// `handlabel adapt`'s synthetic samples in the capture's own look (pipeline/adapt.h):
// the backgrounds stage takes every camera's empty scene from the recording, and the
// training mixes in hands rendered with the capture's cameras over those backgrounds,
// placed where the fit labels put the hand. Their targets are exact, where the capture's
// own samples only have the fit's answers to learn from.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include "capture/frame_images.h"
#include "capture/native_frame_source.h"
#include "core/errors.h"
#include "image/draw.h"
#include "image/median_image.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace adapt {
namespace {

namespace fs = std::filesystem;

// Frames the median is taken over: enough that a hand which stays a while somewhere
// still leaves most of them free there; few enough to read in seconds.
constexpr size_t kBackgroundFrames = 30;
// SNAP keypoint order (hand/hand_model.h): the wrist and the middle finger's MCP joint,
// whose direction continues into the forearm.
constexpr int kWrist = 0;
constexpr int kMiddleMcp = 9;

std::string BackgroundPath(const AdaptRun& run, const std::string& camera) {
  return run.Path("backgrounds/" + camera + ".png");
}

// `count` frames spread evenly over `frames` (all of them when there are fewer).
std::vector<std::string> SpreadFrames(const std::vector<std::string>& frames,
                                      size_t count) {
  if (frames.size() <= count) return frames;
  std::vector<std::string> chosen;
  for (size_t i = 0; i < count; ++i) chosen.push_back(frames[i * frames.size() / count]);
  return chosen;
}

// Where the labelled hand covers a view: discs around its keypoints and a band along
// the forearm (the wrist continued away from the fingers for three hand lengths), as
// wide as a third of the hand's extent in the image. 255 = covered.
ImageU8 HandCover(const RigCamera& camera, const Points3d& keypoints) {
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

// The labels' spread in the world: the hand centres' per-axis median, and the distance
// from it within which 80 % of them lie (at least 3 cm, at most 25 cm).
void Workspace(const std::vector<LabeledFrame>& labels, Eigen::Vector3d* center,
               double* radius) {
  std::vector<Eigen::Vector3d> centres;
  for (const LabeledFrame& f : labels) centres.push_back(f.keypoints_3d.colwise().mean());
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

// The capture's cameras as the renderer needs them: pinhole, without lens distortion
// (training crops are pinhole; near the image centre, where hands are, the difference
// to the photographs' distorted scene is small).
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

}  // namespace

void BackgroundsStage(const AdaptRun& run) {
  const std::vector<std::string> frames =
      SpreadFrames(WithFitLabel(run, run.frames), kBackgroundFrames);
  if (frames.empty()) {
    throw InputError(
        run.Path("fit/labels"), "labels",
        "fit labels of some frames (to leave the hand out of the backgrounds)", "none");
  }
  const NativeFrameSource source(run.o.capture_dir);
  std::vector<std::vector<ImageU8>> images, covers;  // [camera][frame]
  Rig rig;
  for (const std::string& id : frames) {
    FrameInput frame = source.Load(id);
    DecodeFrameImages(&frame);
    const LabelRecord label = ReadLabelFile(LabelFilePath(run.Path("fit"), id));
    rig = frame.rig;
    images.resize(rig.size());
    covers.resize(rig.size());
    for (size_t c = 0; c < rig.size(); ++c) {
      if (frame.images[c].empty()) continue;  // a view without an image
      images[c].push_back(std::move(frame.images[c]));
      covers[c].push_back(HandCover(rig[c], label.mesh.keypoints));
    }
  }
  for (size_t c = 0; c < rig.size(); ++c) {
    if (images[c].empty()) {
      throw InputError(
          run.o.capture_dir, "images of camera " + rig[c].name,
          "an image in some of the frames " + frames.front() + " .. " + frames.back(),
          "none");
    }
    WritePng(BackgroundPath(run, rig[c].name), MedianImage(images[c], covers[c]));
  }
  run.Say("backgrounds: the median of " + std::to_string(frames.size()) +
          " frames per camera, the labelled hand left out (" + run.Path("backgrounds") +
          ")");
}

std::unique_ptr<SynthTrainingSamples> CaptureLookSynthSamples(
    const AdaptRun& run, const FrameSource& capture, const HandModel& hand,
    const std::vector<LabeledFrame>& labels, const TrainingSampleOptions& samples) {
  const Rig rig = PinholeRig(capture.Load(labels.front().id).rig);
  auto photos = std::make_shared<std::vector<ImageU8>>();
  for (const RigCamera& c : rig.cameras()) {
    photos->push_back(ReadPng(BackgroundPath(run, c.name)));
  }
  SynthCaptureOptions o;
  o.seed = run.o.seed;
  o.view.appearance = SynthAppearance::kRealistic;
  o.view.photo_backgrounds = photos;
  o.view.depth = false;
  o.write_detections = false;
  o.scene.objects = true;
  o.scene.object_probability = 0.5;  // hands holding objects and empty hands
  Workspace(labels, &o.scene.workspace_center, &o.scene.workspace_radius);
  return std::make_unique<SynthTrainingSamples>(hand, rig, o, samples);
}

}  // namespace adapt
}  // namespace handlabel
