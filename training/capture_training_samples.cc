#include "training/capture_training_samples.h"

#include <algorithm>
#include <numeric>

#include "capture/frame_images.h"
#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "image/gaussian_blur.h"

namespace handlabel {
namespace {

constexpr uint64_t kOrderStream = 0x0DE5;
constexpr uint64_t kViewStream = 0xCA97;

// Each labelled frame must be usable as a target: 21 finite keypoints, finite vertices.
void CheckLabels(const std::vector<LabeledFrame>& frames) {
  const std::string source = "capture training samples";
  if (frames.empty()) {
    throw InputError(source, "labelled frames", "at least one", "none");
  }
  for (const LabeledFrame& f : frames) {
    if (f.keypoints_3d.rows() != 21 || !f.keypoints_3d.allFinite()) {
      throw InputError(source + ", frame " + f.id, "keypoints_3d", "21 finite keypoints",
                       std::to_string(f.keypoints_3d.rows()) + " rows, finite: " +
                           (f.keypoints_3d.allFinite() ? "yes" : "no"));
    }
    if (f.vertices.rows() == 0 || !f.vertices.allFinite()) {
      throw InputError(source + ", frame " + f.id, "vertices", "finite vertices",
                       std::to_string(f.vertices.rows()) +
                           " rows, finite: " + (f.vertices.allFinite() ? "yes" : "no"));
    }
  }
}

// The augmentations on the pixels, in the order a camera would apply them: optics
// (blur), sensor (noise), then colour (gain) and the occluding noise rectangle.
void AugmentCropPixels(const CaptureViewDraws& d, int S, std::vector<float>* pixels) {
  CropLevelsFromNormalised(pixels);
  GaussianBlurInPlace(d.blur_sigma_px, FloatImageLayout::Planar(S, S, 3), pixels->data());
  std::mt19937_64 noise_rng(d.noise_seed);
  AddPixelNoise(d.noise_sigma, noise_rng, pixels);
  ApplyGainAndNoiseRect(d.augmentation, S, pixels);
  NormaliseCropLevels(pixels);
}

// Where the detections locate the hand in fewer than two views (inference could not
// triangulate such a frame and fits it instead), the views they miss take the label's
// windows at weight 1.
void UseLabelWindows(const FrameInput& frame, const Points3d& keypoints_world,
                     std::vector<CaptureViewDraws>* draws,
                     std::vector<CaptureViewCrop>* crops, const HandCropOptions& crop) {
  for (size_t v = 0; v < crops->size(); ++v) {
    if ((*crops)[v].weight > 0) continue;
    (*draws)[v].from_detection = false;
    (*crops)[v] = CaptureViewWindow(frame, v, keypoints_world, (*draws)[v], crop);
  }
}

Eigen::Matrix4d ToMatrix4(const Rigid3& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topRows<3>() = t.ToMatrix();
  return m;
}

}  // namespace

void CaptureSampleOptions::Check(const std::string& source) const {
  if (crop_size < 32 || crop_size % 32 != 0) {
    throw InputError(source, "crop_size", "a positive multiple of 32",
                     std::to_string(crop_size));
  }
  RequireInRange(source, "detection_crop_probability", detection_crop_probability, 0, 1);
  RequireInRange(source, "shift_sigma", shift_sigma, 0, 0.5);
  RequireInRange(source, "blur_max_px", blur_max_px, 0, 5);
  RequireInRange(source, "noise_max", noise_max, 0, 50);
  augment.Check(source + " augmentation");
  if (augment.rotation_probability != 0) {
    throw InputError(source, "augment.rotation_probability",
                     "0 (crops cut from captures are not turned)",
                     OptionValueText(augment.rotation_probability));
  }
}

CaptureViewDraws DrawCaptureView(const CaptureSampleOptions& o, std::mt19937_64& rng) {
  CaptureViewDraws d;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  d.from_detection = unit(rng) < o.detection_crop_probability;
  if (!o.augment.enabled) return d;
  d.augmentation = DrawViewAugmentation(o.augment, o.crop_size, rng);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int axis = 0; axis < 2; ++axis) {
    d.shift[axis] = o.shift_sigma * std::clamp(normal(rng), -2.0, 2.0);
  }
  d.blur_sigma_px = o.blur_max_px * unit(rng);
  d.noise_sigma = o.noise_max * unit(rng);
  d.noise_seed = rng();
  return d;
}

CaptureViewCrop CaptureViewWindow(const FrameInput& frame, size_t v,
                                  const Points3d& keypoints_world,
                                  const CaptureViewDraws& draws,
                                  const HandCropOptions& crop) {
  const RigCamera& cam = frame.rig[v];
  if (draws.from_detection && v < frame.keypoints_2d.size() && frame.keypoints_2d[v]) {
    if (auto window = CropFromKeypoints(*frame.keypoints_2d[v], crop)) {
      return {*window, 1.0f};
    }
    return {WholeImageCrop(cam.camera), 0.0f};  // CropForView's fallback
  }
  std::vector<Eigen::Vector3d> in_cam;
  for (Eigen::Index k = 0; k < keypoints_world.rows(); ++k) {
    in_cam.push_back(cam.cam_from_world * keypoints_world.row(k).transpose());
  }
  std::optional<CropWindow> window = CropFromPrior(cam.camera, in_cam, crop);
  if (!window) return {WholeImageCrop(cam.camera), 1.0f};
  window->side *= draws.augmentation.scale;
  window->center += draws.shift * window->side;
  return {*window, 1.0f};
}

CaptureTrainingSamples::CaptureTrainingSamples(const FrameSource& source,
                                               std::vector<LabeledFrame> frames,
                                               const CaptureSampleOptions& options)
    : source_(source), frames_(std::move(frames)), options_(options) {
  options_.Check("capture training samples");
  CheckLabels(frames_);
  crop_.crop_size = options_.crop_size;
  num_views_ = static_cast<int>(source_.Load(frames_.front().id).rig.size());
}

size_t CaptureTrainingSamples::FrameOfSample(int64_t index) const {
  HL_CHECK(index >= 0, "a sample index >= 0");
  const uint64_t n = frames_.size();
  const uint64_t epoch = static_cast<uint64_t>(index) / n;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::mt19937_64 rng(MixSeed(options_.seed, epoch, kOrderStream));
  std::shuffle(order.begin(), order.end(), rng);
  return order[static_cast<uint64_t>(index) % n];
}

double CaptureTrainingSamples::MissedViewShare() const {
  int64_t views = 0, missed = 0;
  for (const LabeledFrame& label : frames_) {
    const FrameInput frame = source_.Load(label.id);
    for (size_t v = 0; v < frame.rig.size(); ++v) {
      ++views;
      missed += v >= frame.keypoints_2d.size() || !frame.keypoints_2d[v] ||
                !CropFromKeypoints(*frame.keypoints_2d[v], crop_);
    }
  }
  return views > 0 ? static_cast<double>(missed) / static_cast<double>(views) : 0.0;
}

void CaptureTrainingSamples::MakeView(const FrameInput& frame, size_t v,
                                      const LabeledFrame& label,
                                      const CaptureViewDraws& draws,
                                      const CaptureViewCrop& crop,
                                      TrainingView* view) const {
  const RigCamera& cam = frame.rig[v];
  const ImageU8 image = FrameViewImageRgb(frame, v);
  if (image.empty()) {
    throw InputError(frame.id, "images", "an image for every view the network sees",
                     "none for camera " + cam.name);
  }
  view->intrinsics = CropIntrinsics(cam.camera, crop.window, crop_.crop_size);
  view->image = WarpCrop({image.width, image.height, image.data.data()}, cam.camera,
                         crop.window, crop_);
  view->view_weight = crop.weight;
  if (options_.augment.enabled) AugmentCropPixels(draws, crop_.crop_size, &view->image);
  // As the network stage hands the view to the network (pipeline/network_stage.cc).
  const Rigid3 cam_from_master =
      cam.cam_from_world * frame.rig[0].cam_from_world.Inverse();
  view->master_from_cam = ToMatrix4(cam_from_master.Inverse());
  for (int k = 0; k < 21; ++k) {
    const Eigen::Vector3d p = cam.cam_from_world * label.keypoints_3d.row(k).transpose();
    const double z = std::max(p.z(), 1e-6);  // behind the camera: finite, weight 0
    const Eigen::Vector3d uvw =
        view->intrinsics * Eigen::Vector3d(p.x() / z, p.y() / z, 1);
    view->joints_2d.row(k) = uvw.head<2>().transpose();
    view->joints_2d_weight[k] = p.z() > 1e-6 ? 1.0f : 0.0f;
  }
}

TrainingSample CaptureTrainingSamples::Sample(int64_t index) const {
  const size_t which = FrameOfSample(index);
  const LabeledFrame& label = frames_[which];
  const FrameInput frame = source_.Load(label.id);
  if (static_cast<int>(frame.rig.size()) != num_views_) {
    throw InputError(frame.id, "cameras", std::to_string(num_views_) + " views",
                     std::to_string(frame.rig.size()));
  }
  std::mt19937_64 rng(MixSeed(options_.seed, static_cast<uint64_t>(index), kViewStream));
  TrainingSample sample;
  sample.index = index;
  sample.frame = static_cast<int64_t>(which);
  sample.views.resize(num_views_);
  std::vector<CaptureViewDraws> draws(num_views_);
  std::vector<CaptureViewCrop> crops(num_views_);
  int weighted = 0;
  for (int v = 0; v < num_views_; ++v) {
    draws[v] = DrawCaptureView(options_, rng);
    crops[v] = CaptureViewWindow(frame, v, label.keypoints_3d, draws[v], crop_);
    weighted += crops[v].weight > 0;
  }
  if (weighted < 2) UseLabelWindows(frame, label.keypoints_3d, &draws, &crops, crop_);
  for (int v = 0; v < num_views_; ++v) {
    MakeView(frame, v, label, draws[v], crops[v], &sample.views[v]);
  }
  const Rigid3& master_from_world = frame.rig[0].cam_from_world;
  sample.joints_3d = TransformPoints(master_from_world, label.keypoints_3d);
  sample.vertices_3d = TransformPoints(master_from_world, label.vertices);
  return sample;
}

}  // namespace handlabel
