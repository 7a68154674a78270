#pragma once
// The labeling job's network stage (label_stages.h NetworkStage) on the one network
// interface, network/poem/hand_mesh_predictor.h: per view it reads the image and crops
// around the hand (the frame's 2D keypoints locate it, else its crop prior;
// network/poem/hand_crop.h), runs
// the network in batches, and brings the answer back to the job's conventions: 3D points
// from the master camera's frame to the rig's world frame, 2D keypoints from crop
// pixels to full-image (distorted) pixels with the heatmap peaks as confidences, and
// the mask head's crop masks (if the network has one) to full-image silhouettes.

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "network/poem/hand_crop.h"
#include "network/poem/hand_mesh_predictor.h"
#include "pipeline/job_config.h"
#include "pipeline/label_stages.h"

namespace handlabel {

// The network's input for one frame (view 0 is the master) and, per view, the crop it
// was cut with. Throws InputError naming the frame or image when the rig does not fit
// the network or an image is not RGB.
HandMeshInput CropFrameForNetwork(const FrameInput& frame, int num_views,
                                  const HandCropOptions& crop,
                                  std::vector<ViewCrop>* crops);

// The network's answer for `frame` (made from `crops`) in the rig's world frame and
// full-image pixels; the mask head's masks only with `image_masks` (a full-image
// mask per view costs more than the rest of this together).
MeshPrediction PredictionInRig(const HandMeshPrediction& out, const FrameInput& frame,
                               const std::vector<ViewCrop>& crops, int crop_size,
                               bool image_masks = true);

// The network's answers by input, shared by jobs that show the same weights the same
// frames (the methods of a comparison): each distinct input is predicted once.
// Thread-safe (network lanes call it at once).
class PredictionMemo {
 public:
  // The key of `input` for the weights with hash `weights_sha256`: a SHA-256 of every
  // view's crop pixels, crop intrinsics, pose and weight.
  static std::string Key(const std::string& weights_sha256, const HandMeshInput& input);
  bool Find(const std::string& key, HandMeshPrediction* prediction) const;
  // `seconds`: what predicting it cost (its share of the batch).
  void Store(const std::string& key, const HandMeshPrediction& prediction,
             double seconds);
  int hits() const;  // answers given from the memo so far
  // The network time those answers had cost: a job's timing plus this delta is what
  // the job would have taken alone.
  double saved_seconds() const;

 private:
  struct Entry {
    HandMeshPrediction prediction;
    double seconds = 0;
  };
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
  mutable int hits_ = 0;
  mutable double saved_seconds_ = 0;
};

// The two above around one Predict call of `network`; with a memo, only the frames
// whose input it has not seen go to the network.
std::vector<MeshPrediction> PredictFramesInRig(
    HandMeshPredictor& network, const std::vector<const FrameInput*>& frames,
    PredictionMemo* memo = nullptr, const std::string& weights_sha256 = "",
    bool image_masks = true);

// The job's network stage from its `network` section (weights, batch_size, threads):
// loads and validates the weights (InputError naming the file) and hashes them. Its
// answers carry masks only when the job fits to them (evidence.masks: network). This is
// where capture/'s frames meet network/'s predictor, so it lives in pipeline/. With a
// memo, inputs seen before are answered from it.
NetworkStage LoadNetworkStage(const JobConfig& job,
                              std::shared_ptr<PredictionMemo> memo = nullptr);

// Makes `stage` read its answers' keypoints as the job's network.keypoints says
// (hand/mesh_keypoints.h) and names the reading in stage->keypoints. The mesh readings
// need `hand` in the network's topology (POEM: 778 vertices); with another hand model
// (the capsule hand) the joints are read, and stage->keypoints says why.
void ReadAnswerKeypointsAs(const JobConfig& job, const HandModel& hand,
                           NetworkStage* stage);

}  // namespace handlabel
