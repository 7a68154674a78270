#pragma once
// The labeling job's network stage (label_stages.h NetworkStage) on the one network
// interface, network/hand_mesh_predictor.h: per view it reads the image and crops
// around the hand (the capture's 2D keypoints locate it; network/hand_crop.h), runs the
// network in batches, and brings the answer back to the job's conventions: 3D points
// from the master camera's frame to the rig's world frame, 2D keypoints from crop
// pixels to full-image (distorted) pixels with the heatmap peaks as confidences, and
// the mask head's crop masks (if the network has one) to full-image silhouettes.

#include <string>
#include <vector>

#include "network/hand_crop.h"
#include "network/hand_mesh_predictor.h"
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
// full-image pixels.
MeshPrediction PredictionInRig(const HandMeshPrediction& out, const FrameInput& frame,
                               const std::vector<ViewCrop>& crops, int crop_size);

// The two above around one Predict call of `network`.
std::vector<MeshPrediction> PredictFramesInRig(
    HandMeshPredictor& network, const std::vector<const FrameInput*>& frames);

// The job's network stage from its `network` section (weights, batch_size, threads):
// loads and validates the weights (InputError naming the file) and hashes them. This is
// where capture/'s frames meet network/'s predictor, so it lives in pipeline/.
NetworkStage LoadNetworkStage(const JobConfig& job);

}  // namespace handlabel
