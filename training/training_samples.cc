#include "training/training_samples.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "core/text.h"
#include "network/poem/hand_crop.h"

namespace handlabel {
namespace {

constexpr uint64_t kAugmentStream = 0xA06E;
constexpr uint64_t kMissedViewStream = 0xD40F;

using Affine2 = Eigen::Matrix<double, 2, 3>;  // crop pixel = A * (x, y, 1)

Eigen::Matrix4d ToMatrix4(const Rigid3& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = t.rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = t.translation;
  return m;
}

// Bilinear sample of channel c at (x, y) with zero outside the image.
float Bilinear(const ImageU8& img, double x, double y, int c) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double ax = x - x0, ay = y - y0;
  auto at = [&](int xi, int yi) -> double {
    return img.Contains(xi, yi) ? img.at(xi, yi, c) : 0.0;
  };
  const double top = (1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0);
  const double bottom = (1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1);
  return static_cast<float>((1 - ay) * top + ay * bottom);
}

using Keypoints2d = Eigen::Matrix<double, 21, 2, Eigen::RowMajor>;

// The 21 keypoints projected exactly (pinhole), their weights (0 behind the camera)
// and the box of the weighted ones (the principal point if none).
void ProjectKeypoints(const RigCamera& cam, const Eigen::Matrix4d& cam_from_world,
                      const Points3d& keypoints, Keypoints2d* uv,
                      std::array<float, 21>* weight, Eigen::Vector2d* lo,
                      Eigen::Vector2d* hi) {
  const double fx = cam.camera.fx(), fy = cam.camera.fy();
  const double cx = cam.camera.cx(), cy = cam.camera.cy();
  *lo = Eigen::Vector2d(1e300, 1e300);
  *hi = Eigen::Vector2d(-1e300, -1e300);
  for (int k = 0; k < 21; ++k) {
    const Eigen::Vector3d p =
        (cam_from_world * keypoints.row(k).transpose().homogeneous()).head<3>();
    const double z = std::max(p.z(), 1e-6);
    uv->row(k) << fx * p.x() / z + cx, fy * p.y() / z + cy;
    (*weight)[k] = p.z() > 1e-6 ? 1.0f : 0.0f;
    if ((*weight)[k] > 0) {
      *lo = lo->cwiseMin(uv->row(k).transpose());
      *hi = hi->cwiseMax(uv->row(k).transpose());
    }
  }
  if (lo->x() > hi->x()) *lo = *hi = Eigen::Vector2d(cx, cy);  // hand behind the camera
}

// The crop of one view: crop pixel = lin * image pixel + offset, with lin = s * rot *
// diag(f / fx, f / fy) (square pixels of focal length f, turned, scaled to the crop).
struct CropTransform {
  Eigen::Matrix2d rot;
  Eigen::Matrix2d lin;
  Affine2 affine;
  double f = 0, s = 0;
};

// `center` in image pixels, `side` in square pixels of focal length f.
CropTransform MakeCropTransform(const Camera& camera, const Eigen::Vector2d& center,
                                double side, const ViewAugmentation& aug,
                                const TrainingSampleOptions& o) {
  const double fx = camera.fx(), fy = camera.fy();
  CropTransform t;
  t.f = 0.5 * (fx + fy);
  t.s = o.crop_size / side;
  const double co = std::cos(aug.rotation_rad), si = std::sin(aug.rotation_rad);
  t.rot << co, -si, si, co;
  t.lin = t.s * t.rot * Eigen::Vector2d(t.f / fx, t.f / fy).asDiagonal();
  t.affine.leftCols<2>() = t.lin;
  t.affine.col(2) = Eigen::Vector2d::Constant(0.5 * o.crop_size) -
                    t.lin * center;  // as network/poem/hand_crop.h
  return t;
}

// Resamples the image (gain, noise rectangle) and the hand mask through the inverse
// crop transform into the network's layout.
void ResampleCrop(const SynthView& src, const CropTransform& t,
                  const ViewAugmentation& aug, const TrainingSampleOptions& o,
                  TrainingView* view) {
  const int S = o.crop_size;
  const Eigen::Matrix2d inv = t.lin.inverse();
  const Eigen::Vector2d inv_t = -inv * t.affine.col(2);
  view->image.assign(3 * S * S, 0.0f);
  if (o.masks) view->mask.assign(S * S, 0.0f);
  for (int y = 0; y < S; ++y) {
    for (int x = 0; x < S; ++x) {
      const Eigen::Vector2d p = inv * Eigen::Vector2d(x, y) + inv_t;
      for (int ch = 0; ch < 3; ++ch) {
        view->image[(ch * S + y) * S + x] = Bilinear(src.rgb, p.x(), p.y(), ch);
      }
      if (o.masks)
        view->mask[y * S + x] = Bilinear(src.hand_mask, p.x(), p.y(), 0) / 255.0f;
    }
  }
  ApplyGainAndNoiseRect(aug, S, &view->image);
  NormaliseCropLevels(&view->image);
}

// One view of the sample; returns the (turned) camera's cam_from_world. Throws
// InputError for a camera with lens distortion.
Eigen::Matrix4d MakeTrainingView(const RigCamera& cam, const SynthView& src,
                                 const Points3d& keypoints, const ViewAugmentation& aug,
                                 bool missed, const TrainingSampleOptions& o,
                                 TrainingView* view) {
  const CameraModelId model = cam.camera.model();
  if (model != CameraModelId::kPinhole && model != CameraModelId::kSimplePinhole) {
    throw InputError("training samples", "camera " + cam.name,
                     "a pinhole camera (crops assume no lens distortion)",
                     CameraModelName(model));
  }
  const Eigen::Matrix4d original = ToMatrix4(cam.cam_from_world);
  // Keypoint box from the exact projections (points behind the camera are skipped).
  Keypoints2d uv;
  std::array<float, 21> weight{};
  Eigen::Vector2d lo, hi;
  ProjectKeypoints(cam, original, keypoints, &uv, &weight, &lo, &hi);
  CropTransform t;
  if (missed) {  // as inference crops a view whose detection missed the hand
    ViewAugmentation plain = aug;
    plain.scale = 1;
    plain.rotation_rad = 0;
    const CropWindow whole = WholeImageCrop(cam.camera);
    t = MakeCropTransform(cam.camera, whole.center, whole.side, plain, o);
  } else {
    // The box is measured in square pixels.
    const double f = 0.5 * (cam.camera.fx() + cam.camera.fy());
    const double box = std::max({(hi.x() - lo.x()) * f / cam.camera.fx(),
                                 (hi.y() - lo.y()) * f / cam.camera.fy(), o.min_box_px});
    t = MakeCropTransform(cam.camera, 0.5 * (lo + hi), box * o.box_scale * aug.scale, aug,
                          o);
  }
  view->view_weight = missed ? 0.0f : 1.0f;

  const Eigen::Vector2d pp =
      t.lin * Eigen::Vector2d(cam.camera.cx(), cam.camera.cy()) + t.affine.col(2);
  view->intrinsics << t.s * t.f, 0, pp.x(), 0, t.s * t.f, pp.y(), 0, 0, 1;
  for (int k = 0; k < 21; ++k) {
    view->joints_2d.row(k) =
        (t.lin * uv.row(k).transpose() + t.affine.col(2)).transpose();
  }
  view->joints_2d_weight = weight;
  ResampleCrop(src, t, aug, o, view);
  Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
  turn.topLeftCorner<2, 2>() = t.rot;  // cam' = turn * cam
  return turn * original;
}

// World points in the master frame.
Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> ToMaster(
    const Eigen::Matrix4d& master_from_world, const Points3d& world) {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> out(world.rows(), 3);
  const Eigen::Matrix3d R = master_from_world.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = master_from_world.topRightCorner<3, 1>();
  for (Eigen::Index i = 0; i < world.rows(); ++i) {
    out.row(i) = (R * world.row(i).transpose() + t).transpose();
  }
  return out;
}

}  // namespace

void TrainingSampleOptions::Check(const std::string& source) const {
  if (crop_size < 32 || crop_size % 32 != 0) {
    throw InputError(source, "crop_size", "a positive multiple of 32",
                     std::to_string(crop_size));
  }
  RequireGreater(source, "box_scale", box_scale, 0);
  RequireGreater(source, "min_box_px", min_box_px, 0);
  RequireAtLeast(source, "frame_reuse", frame_reuse, 1);
  RequireAtLeast(source, "reuse_group", reuse_group, 1);
  RequireInRange(source, "view_dropout", view_dropout, 0, 1, "0..1");
  augment.Check(source + " augmentation");
}

int64_t TrainingFrameOf(int64_t index, const TrainingSampleOptions& o) {
  const int64_t group = o.reuse_group, block = group * o.frame_reuse;
  return (index / block) * group + index % group;
}

std::vector<bool> DrawMissedViews(double view_dropout, int num_views,
                                  std::mt19937_64& rng) {
  std::vector<bool> missed(num_views, false);
  if (view_dropout <= 0) return missed;
  std::uniform_real_distribution<double> unit(0, 1);
  int kept = 0;
  for (int v = 0; v < num_views; ++v) {
    missed[v] = unit(rng) < view_dropout;
    kept += !missed[v];
  }
  if (kept >= 2) return missed;
  std::vector<int> order(num_views);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  for (int v : order) {
    if (kept >= 2) break;
    if (missed[v]) {
      missed[v] = false;
      ++kept;
    }
  }
  return missed;
}

TrainingSample MakeTrainingSample(const SynthFrame& frame, const Rig& rig,
                                  const TrainingSampleOptions& o,
                                  const std::vector<ViewAugmentation>& augmentations,
                                  const std::vector<bool>& missed) {
  const int N = static_cast<int>(rig.size());
  HL_CHECK(static_cast<int>(frame.views.size()) == N, "one rendered view per camera");
  HL_CHECK(static_cast<int>(augmentations.size()) == N, "one augmentation per view");
  HL_CHECK(missed.empty() || static_cast<int>(missed.size()) == N, "one flag per view");
  const Points3d& keypoints = frame.scene.hand.keypoints;  // world, SNAP order

  TrainingSample sample;
  sample.frame = frame.index;
  sample.views.resize(N);
  std::vector<Eigen::Matrix4d> cam_from_world(N);
  for (int c = 0; c < N; ++c) {
    cam_from_world[c] =
        MakeTrainingView(rig[c], frame.views[c], keypoints, augmentations[c],
                         !missed.empty() && missed[c], o, &sample.views[c]);
  }
  // Master frame = the (turned) camera 0.
  const Eigen::Matrix4d master_from_world = cam_from_world[0];
  for (int c = 0; c < N; ++c) {
    sample.views[c].master_from_cam = master_from_world * cam_from_world[c].inverse();
  }
  sample.views[0].master_from_cam = Eigen::Matrix4d::Identity();
  sample.joints_3d = ToMaster(master_from_world, keypoints);
  sample.vertices_3d = ToMaster(master_from_world, frame.scene.hand.vertices);
  return sample;
}

SynthTrainingSamples::SynthTrainingSamples(const HandModel& model,
                                           const SynthCaptureOptions& synth,
                                           const TrainingSampleOptions& options)
    : SynthTrainingSamples(model, MakePresetRig(synth.rig, synth.seed), synth, options) {}

SynthTrainingSamples::SynthTrainingSamples(const HandModel& model, Rig rig,
                                           const SynthCaptureOptions& synth,
                                           const TrainingSampleOptions& options)
    : generator_(model, std::move(rig),
                 [&] {
                   SynthCaptureOptions s = synth;
                   s.view.depth = false;
                   s.write_detections = false;
                   return s;
                 }()),
      options_(options) {
  options_.Check("training samples");
}

std::shared_ptr<const SynthFrame> SynthTrainingSamples::Frame(int64_t frame_index) const {
  {
    std::lock_guard<std::mutex> lock(cache_mutex_);
    for (const auto& [index, frame] : cache_) {
      if (index == frame_index) return frame;
    }
  }
  auto frame = std::make_shared<const SynthFrame>(
      generator_.Generate(static_cast<int>(frame_index)));
  std::lock_guard<std::mutex> lock(cache_mutex_);
  cache_.emplace_back(frame_index, frame);
  const size_t keep = 2 * static_cast<size_t>(options_.reuse_group);
  if (cache_.size() > keep) cache_.erase(cache_.begin(), cache_.end() - keep);
  return frame;
}

TrainingSample SynthTrainingSamples::Sample(int64_t index) const {
  const std::shared_ptr<const SynthFrame> frame = Frame(TrainingFrameOf(index, options_));
  std::mt19937_64 rng(MixSeed(options_.augment_seed, index, kAugmentStream));
  std::vector<ViewAugmentation> augs;
  for (int c = 0; c < num_views(); ++c) {
    augs.push_back(DrawViewAugmentation(options_.augment, options_.crop_size, rng));
  }
  std::mt19937_64 missed_rng(MixSeed(options_.augment_seed, index, kMissedViewStream));
  const std::vector<bool> missed =
      DrawMissedViews(options_.view_dropout, num_views(), missed_rng);
  TrainingSample sample =
      MakeTrainingSample(*frame, generator_.rig(), options_, augs, missed);
  sample.index = index;
  return sample;
}

}  // namespace handlabel
