#pragma once
// The labeling job's network stage (label_stages.h MeshPredictor) on the torch-free
// network/hand_mesh_predictor.h: per view it reads the image, crops around the hand
// (the capture's 2D detections locate it; network/hand_crop.h), runs the network in
// batches, and brings the answer back to the job's conventions: 3D points from the
// master camera's frame to the rig's world frame, 2D keypoints from crop pixels to
// full-image (distorted) pixels, per-keypoint heatmap peaks as confidences, and the
// mask head's crop masks (if the network has one) to full-image silhouettes.

#include <memory>
#include <string>

#include "network/hand_crop.h"
#include "network/hand_mesh_predictor.h"
#include "pipeline/label_stages.h"

namespace handlabel {

class PoemMeshPredictor : public MeshPredictor {
 public:
  // Loads and validates the weights (InputError naming the file); hashes them.
  PoemMeshPredictor(const std::string& weights, int batch_size, int num_threads);
  std::string ModelName() const override;
  std::string WeightsSha256() const override { return weights_sha256_; }
  bool PredictsMasks() const override { return network_->predicts_masks(); }
  std::vector<MeshPrediction> Predict(
      const std::vector<const FrameInput*>& frames) override;

 private:
  std::unique_ptr<HandMeshPredictor> network_;
  std::string weights_;
  std::string weights_sha256_;
  HandCropOptions crop_;
};

}  // namespace handlabel
