#pragma once
// Conversion of torch-free frame data (hand_mesh_predictor.h) into POEM tensors, for
// inference and for training code. Internal to network/ (includes LibTorch).

#include <torch/torch.h>

#include <vector>

#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_loss.h"
#include "network/poem/poem_model.h"

namespace handlabel {

// Ground truth of one frame in the master frame (view 0), for training.
struct HandMeshTargets {
  Keypoints3 joints;                                                   // SNAP order
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertices;  // 778 x 3
  std::vector<KeypointPixels> joints_2d;  // per view, crop pixels
  // Optional per view: 0 drops the view from the 2D terms (hand not visible).
  std::vector<double> view_weights;
};

// frames[begin, end) -> a batch (images, intrinsics, master_from_cam, view weights).
// Frames must already be valid for the config (HandMeshPredictor::Predict checks).
PoemBatch MakePoemBatch(const std::vector<HandMeshInput>& frames, size_t begin,
                        size_t end, const PoemConfig& config);

// targets[begin, end) -> PoemTargets. Throws InputError naming the frame if a size is
// wrong.
PoemTargets MakePoemTargets(const std::vector<HandMeshTargets>& targets, size_t begin,
                            size_t end, const PoemConfig& config);

}  // namespace handlabel
