#include "pipeline/poem_mesh_predictor.h"

#include <filesystem>

#include "core/errors.h"
#include "core/image.h"
#include "core/image_file.h"
#include "core/sha256.h"

namespace handlabel {

PoemMeshPredictor::PoemMeshPredictor(const std::string& weights, int batch_size,
                                     int num_threads)
    : weights_(weights) {
  HandMeshPredictorOptions options;
  options.weights = weights;
  options.batch_size = batch_size;
  options.num_threads = num_threads;
  network_ = CreateHandMeshPredictor(options);
  weights_sha256_ = Sha256OfFile(weights);
  crop_.crop_size = network_->crop_size();
}

std::string PoemMeshPredictor::ModelName() const {
  return network_->name() + " (" + std::filesystem::path(weights_).filename().string() +
         ")";
}

std::vector<MeshPrediction> PoemMeshPredictor::Predict(
    const std::vector<const FrameInput*>& frames) {
  std::vector<HandMeshInput> inputs;
  std::vector<std::vector<ViewCrop>> crops;
  for (const FrameInput* frame : frames) {
    const Rig& rig = frame->rig;
    if (static_cast<int>(rig.size()) != network_->num_views()) {
      throw InputError(frame->id, "cameras",
                       std::to_string(network_->num_views()) + " views for this network",
                       std::to_string(rig.size()));
    }
    HandMeshInput input;
    crops.emplace_back();
    for (size_t v = 0; v < rig.size(); ++v) {
      const ImageU8 image = ReadImageFile(frame->image_paths.at(v));
      if (image.channels != 3) {
        throw InputError(frame->image_paths[v], "channels", "an RGB image",
                         std::to_string(image.channels));
      }
      HandEvidence evidence;
      if (!frame->keypoints_2d.empty() && frame->keypoints_2d[v]) {
        for (int k = 0; k < kNumHandKeypoints; ++k) {
          evidence.keypoints.push_back(frame->keypoints_2d[v]->uv_px.row(k).transpose());
          evidence.confidences.push_back(frame->keypoints_2d[v]->confidence(k));
        }
      }
      ViewCrop crop = CropForView({image.width, image.height, image.data.data()},
                                  rig[v].camera, evidence, crop_);
      HandMeshViewInput view;
      view.pixels = std::move(crop.pixels);
      view.intrinsics = crop.intrinsics;
      view.cam_from_master = rig[v].cam_from_world * rig[0].cam_from_world.Inverse();
      view.weight = crop.hand_visible ? 1.0 : 0.0;
      input.views.push_back(std::move(view));
      crops.back().push_back(std::move(crop));
    }
    inputs.push_back(std::move(input));
  }
  const std::vector<HandMeshPrediction> outputs = network_->Predict(inputs);
  HL_CHECK(outputs.size() == frames.size(), "one prediction per frame");

  std::vector<MeshPrediction> predictions;
  for (size_t f = 0; f < frames.size(); ++f) {
    const Rig& rig = frames[f]->rig;
    const HandMeshPrediction& out = outputs[f];
    const Rigid3 world_from_master = rig[0].cam_from_world.Inverse();
    MeshPrediction p;
    p.keypoints.resize(kNumHandKeypoints, 3);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      p.keypoints.row(k) =
          (world_from_master * out.joints.row(k).transpose()).transpose();
    }
    p.vertices.resize(out.vertices.rows(), 3);
    for (int i = 0; i < out.vertices.rows(); ++i) {
      p.vertices.row(i) =
          (world_from_master * out.vertices.row(i).transpose()).transpose();
    }
    for (size_t v = 0; v < rig.size(); ++v) {
      // A crop pixel is a ray of the view's camera (same rotation, pinhole K_crop);
      // projecting that ray with the real camera gives the full-image pixel.
      const Eigen::Matrix3d crop_from_ray = crops[f][v].intrinsics;
      Keypoints2dView view;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const Eigen::Vector3d ray =
            crop_from_ray.inverse() *
            Eigen::Vector3d(out.joints_2d[v](k, 0), out.joints_2d[v](k, 1), 1.0);
        Eigen::Vector2d uv;
        const bool in_front = rig[v].camera.Project(ray, &uv);
        view.uv_px.row(k) = uv.transpose();
        view.confidence(k) =
            in_front && crops[f][v].hand_visible ? out.joint_confidence[v](k) : 0.0;
      }
      p.keypoints_2d.push_back(view);
      if (!out.masks.empty()) {
        const int cell = network_->crop_size() / static_cast<int>(out.masks[v].rows());
        MaskImage mask =
            CropMaskToImage(out.masks[v], cell, crops[f][v].intrinsics, rig[v].camera);
        // An empty prediction says "no hand here", which the silhouette term would
        // enforce; treat it as no evidence instead (the keypoints decide).
        if ((mask.array() == 0).all()) mask = MaskImage();
        p.masks.push_back(std::move(mask));
      }
    }
    predictions.push_back(std::move(p));
  }
  return predictions;
}

}  // namespace handlabel
