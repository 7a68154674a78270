#include "pipeline/network_stage.h"

#include <algorithm>
#include <filesystem>
#include <memory>
#include <thread>

#include "capture/frame_images.h"
#include "core/errors.h"
#include "core/stopwatch.h"
#include "formats/sha256.h"
#include "image/image.h"
#include "network/poem/poem_config.h"

namespace handlabel {
namespace {

// A crop pixel is a ray of the view's camera (same rotation, pinhole K_crop);
// projecting that ray with the real camera gives the full-image pixel.
Keypoints2d CropKeypointsToImage(const Keypoints2d& in_crop, const ViewCrop& crop,
                                 const Camera& camera) {
  Keypoints2d out;
  const Eigen::Matrix3d crop_from_ray = crop.intrinsics;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const Eigen::Vector3d ray =
        crop_from_ray.inverse() *
        Eigen::Vector3d(in_crop.uv_px(k, 0), in_crop.uv_px(k, 1), 1.0);
    Eigen::Vector2d uv;
    const bool in_front = camera.Project(ray, &uv);
    out.uv_px.row(k) = uv.transpose();
    out.confidence(k) = in_front && crop.hand_visible ? in_crop.confidence(k) : 0.0;
  }
  return out;
}

}  // namespace

HandMeshInput CropFrameForNetwork(const FrameInput& frame, int num_views,
                                  const HandCropOptions& crop,
                                  std::vector<ViewCrop>* crops) {
  const Rig& rig = frame.rig;
  if (static_cast<int>(rig.size()) != num_views) {
    throw InputError(frame.id, "cameras",
                     std::to_string(num_views) + " views for this network",
                     std::to_string(rig.size()));
  }
  HandMeshInput input;
  crops->clear();
  for (size_t v = 0; v < rig.size(); ++v) {
    const ImageU8 image = FrameViewImageRgb(frame, v);
    if (image.empty()) {
      throw InputError(frame.id, "images", "an image for every view the network sees",
                       "none for camera " + rig[v].name);
    }
    HandEvidence evidence;
    if (!frame.keypoints_2d.empty()) evidence.keypoints = frame.keypoints_2d[v];
    for (int p = 0; p < frame.crop_prior.rows(); ++p) {
      evidence.prior_points_in_cam.push_back(rig[v].cam_from_world *
                                             Eigen::Vector3d(frame.crop_prior.row(p)));
    }
    ViewCrop view_crop = CropForView({image.width, image.height, image.data.data()},
                                     rig[v].camera, evidence, crop);
    HandMeshViewInput view;
    view.pixels = std::move(view_crop.pixels);
    view.intrinsics = view_crop.intrinsics;
    view.cam_from_master = rig[v].cam_from_world * rig[0].cam_from_world.Inverse();
    view.weight = view_crop.hand_visible ? 1.0 : 0.0;
    input.views.push_back(std::move(view));
    crops->push_back(std::move(view_crop));
  }
  return input;
}

MeshPrediction PredictionInRig(const HandMeshPrediction& out, const FrameInput& frame,
                               const std::vector<ViewCrop>& crops, int crop_size,
                               bool image_masks) {
  const Rig& rig = frame.rig;
  const Rigid3 world_from_master = rig[0].cam_from_world.Inverse();
  MeshPrediction p;
  p.keypoints = TransformPoints(world_from_master, out.joints);
  p.vertices = TransformPoints(world_from_master, out.vertices);
  for (size_t v = 0; v < rig.size(); ++v) {
    p.keypoints_2d.push_back(
        CropKeypointsToImage(out.joints_2d[v], crops[v], rig[v].camera));
    if (out.masks.empty() || !image_masks) continue;
    const int cell = crop_size / static_cast<int>(out.masks[v].rows());
    MaskImage mask =
        CropMaskToImage(out.masks[v], cell, crops[v].intrinsics, rig[v].camera);
    // An empty prediction says "no hand here", which the silhouette term would
    // enforce; treat it as no evidence instead (the keypoints decide).
    if ((mask.array() == 0).all()) mask = MaskImage();
    p.masks.push_back(std::move(mask));
  }
  return p;
}

std::string PredictionMemo::Key(const std::string& weights_sha256,
                                const HandMeshInput& input) {
  Sha256 hash;
  hash.Update(weights_sha256);
  for (const HandMeshViewInput& view : input.views) {
    hash.Update(view.pixels.data(), view.pixels.size() * sizeof(float));
    hash.Update(view.intrinsics.data(), 9 * sizeof(double));
    const Matrix3x4d pose = view.cam_from_master.ToMatrix();
    hash.Update(pose.data(), 12 * sizeof(double));
    hash.Update(&view.weight, sizeof(double));
  }
  return hash.HexDigest();
}

bool PredictionMemo::Find(const std::string& key, HandMeshPrediction* prediction) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = entries_.find(key);
  if (it == entries_.end()) return false;
  *prediction = it->second.prediction;
  ++hits_;
  saved_seconds_ += it->second.seconds;
  return true;
}

void PredictionMemo::Store(const std::string& key, const HandMeshPrediction& prediction,
                           double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.emplace(key, Entry{prediction, seconds});
}

int PredictionMemo::hits() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return hits_;
}

double PredictionMemo::saved_seconds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return saved_seconds_;
}

std::vector<MeshPrediction> PredictFramesInRig(
    HandMeshPredictor& network, const std::vector<const FrameInput*>& frames,
    PredictionMemo* memo, const std::string& weights_sha256, bool image_masks) {
  HandCropOptions crop;
  crop.crop_size = network.crop_size();
  std::vector<std::vector<ViewCrop>> crops(frames.size());
  std::vector<HandMeshPrediction> outputs(frames.size());
  std::vector<std::string> keys(frames.size());
  std::vector<HandMeshInput> inputs;  // the frames the network has to answer
  std::vector<size_t> asked;
  for (size_t f = 0; f < frames.size(); ++f) {
    HandMeshInput input =
        CropFrameForNetwork(*frames[f], network.num_views(), crop, &crops[f]);
    if (memo) {
      keys[f] = PredictionMemo::Key(weights_sha256, input);
      if (memo->Find(keys[f], &outputs[f])) continue;
    }
    inputs.push_back(std::move(input));
    asked.push_back(f);
  }
  if (!inputs.empty()) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<HandMeshPrediction> answers = network.Predict(inputs);
    HL_CHECK(answers.size() == inputs.size(), "one prediction per frame");
    const double each = SecondsSince(start) / static_cast<double>(inputs.size());
    for (size_t i = 0; i < asked.size(); ++i) {
      if (memo) memo->Store(keys[asked[i]], answers[i], each);
      outputs[asked[i]] = std::move(answers[i]);
    }
  }
  std::vector<MeshPrediction> predictions;
  for (size_t f = 0; f < frames.size(); ++f) {
    predictions.push_back(PredictionInRig(outputs[f], *frames[f], crops[f],
                                          network.crop_size(), image_masks));
  }
  return predictions;
}

NetworkStage LoadNetworkStage(const JobConfig& job,
                              std::shared_ptr<PredictionMemo> memo) {
  const std::string& weights = job.network_weights;
  // Two batches at once, each on half the job's threads: one batch's serial stretches
  // (sampling, kNN, small layers) and the frames' fits then fill the cores instead of
  // idle LibTorch workers (issue 21: 5-10 % of the demo job; docs/labeling-jobs.md).
  // fit.init previous labels frame by frame: its one batch at a time gets them all.
  const int threads =
      job.threads > 0
          ? job.threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int lanes = job.fit.init == "previous" ? 1 : std::min(threads, 2);
  HandMeshPredictorOptions options;
  options.weights = weights;
  options.batch_size = job.batch_size;
  options.num_threads = threads / lanes;
  options.precision = job.network_precision;
  // Shared: std::function needs a copyable callable.
  std::shared_ptr<HandMeshPredictor> network = CreateHandMeshPredictor(options);
  NetworkStage stage;
  stage.model_name =
      network->name() + " (" + std::filesystem::path(weights).filename().string() +
      (network->precision() == "fp32" ? "" : ", " + network->precision()) + ")";
  stage.weights_sha256 = Sha256OfFile(weights);
  if (job.network_precision == "auto") {  // the model name says the arithmetic
    stage.precision = "auto: " + network->precision() +
                      (CpuHasBf16Unit() ? ", the CPU has a bf16 unit"
                                        : ", no bf16 unit on this CPU");
  }
  stage.predicts_masks = network->predicts_masks();
  stage.num_parameters = network->num_parameters();
  stage.lanes = lanes;
  stage.threads_per_batch = options.num_threads;
  const bool image_masks = job.masks == MaskSource::kNetwork;
  stage.predict = [network, memo, sha = stage.weights_sha256,
                   image_masks](const std::vector<const FrameInput*>& frames) {
    return PredictFramesInRig(*network, frames, memo.get(), sha, image_masks);
  };
  return stage;
}

void ReadAnswerKeypointsAs(const JobConfig& job, const HandModel& hand,
                           NetworkStage* stage) {
  const AnswerKeypoints how = job.network_keypoints;
  stage->keypoints = ToString(how);
  if (how == AnswerKeypoints::kJoints) return;
  if (hand.num_vertices() != PoemConfig::kNumVertices) {
    stage->keypoints = "joints (" + ToString(how) + " reads the mesh, whose " +
                       std::to_string(PoemConfig::kNumVertices) +
                       " vertices the hand model's " +
                       std::to_string(hand.num_vertices()) + " do not match)";
    return;
  }
  auto model = std::make_shared<const HandModel>(hand);
  stage->predict = [predict = std::move(stage->predict), model,
                    how](const std::vector<const FrameInput*>& frames) {
    std::vector<MeshPrediction> answers = predict(frames);
    for (MeshPrediction& p : answers) {
      p.keypoints = ReadAnswerKeypoints(*model, p.keypoints, p.vertices, how);
    }
    return answers;
  };
}

}  // namespace handlabel
