#pragma once
// Training losses of POEM (the reference recipe) and one optimisation step.
// Internal to network/ (includes LibTorch); the training loop builds on
//   PoemOutputs out = model->forward(batch);
//   PoemLoss loss = ComputePoemLoss(out, batch, targets, regressor, options);
// or on TrainStep(), which does forward, loss, backward, clipping and the update.

#include <torch/torch.h>

#include <string>
#include <utility>
#include <vector>

#include "hand/hand_model.h"
#include "network/poem/poem_model.h"

namespace handlabel {

// Ground truth of a batch, in the frames of PoemBatch.
struct PoemTargets {
  torch::Tensor joints_3d;    // (B, 21, 3) master frame, metres, SNAP order
  torch::Tensor vertices_3d;  // (B, 778, 3) master frame, metres
  torch::Tensor joints_2d;    // (B, N, 21, 2) crop pixels, corner convention
  // Optional (B, N, 21) weights of the 2D terms (0 for views where the hand is not
  // visible); undefined = all ones (the reference).
  torch::Tensor joints_2d_weights;
  // Optional (B, N, M, M) hand-mask coverage in [0, 1] at the mask head's resolution
  // (PoemConfig::mask_size); used when the model has a mask head.
  torch::Tensor masks;
};

// Weights of the reference (config LOSS section of the released configs).
struct PoemLossOptions {
  double heatmap_weight = 10.0;  // 2D soft-argmax joints vs targets, / crop diagonal
  double triangulation_weight = 10.0;  // MSE of the triangulated joints
  double joints_weight = 1.0;          // per layer: joint MSE + regressed-joint MSE
  double vertices_weight = 1.0;        // per layer: vertex L1
  double joints_2d_weight = 1.0;       // per layer: clamped reprojection of the joints
  double mask_weight = 1.0;  // mask head (ours): binary cross-entropy of the logits
  // Throws InputError for negative weights.
  void Check(const std::string& source) const;
};

struct PoemLoss {
  torch::Tensor total;  // scalar, differentiable
  // Named scalar terms (unweighted): heatmap_joints, triangulated_joints,
  // dec<i>_recon (weighted sum of layer i), and for the last layer joints_3d,
  // joints_3d_from_mesh, vertices_3d, joints_2d; masks when the model has a mask head
  // and the targets have masks.
  std::vector<std::pair<std::string, torch::Tensor>> terms;
};

// Mean binary cross-entropy of mask logits against coverage targets (same shape).
torch::Tensor PoemMaskLoss(const torch::Tensor& logits, const torch::Tensor& coverage);

// regressor (21, 778): keypoints (SNAP order) as linear functions of the vertices,
// e.g. PoemKeypointRegressor(hand_model).
PoemLoss ComputePoemLoss(const PoemOutputs& outputs, const PoemBatch& batch,
                         const PoemTargets& targets, const torch::Tensor& regressor,
                         const PoemLossOptions& options = {});

// The 21 x 778 keypoint regressor of a hand model: its joint regressor for the 16
// joints, one-hot rows for the fingertip vertices (model.tip_vertex_ids; POEM uses
// {744, 320, 443, 555, 672}), rows in SNAP order.
torch::Tensor PoemKeypointRegressor(const HandModel& model);

struct TrainStepOptions {
  // Each parameter's gradient is scaled to at most this L2 norm (the reference clips
  // per parameter at 1.0); 0 disables clipping.
  double grad_clip_norm = 1.0;
};

struct TrainStepResult {
  double total = 0;
  std::vector<std::pair<std::string, double>> terms;
};

// model->train(); forward; loss; backward; per-parameter clipping; optimizer step.
TrainStepResult TrainStep(PoemModel& model, torch::optim::Optimizer& optimizer,
                          const PoemBatch& batch, const PoemTargets& targets,
                          const torch::Tensor& regressor,
                          const PoemLossOptions& loss_options = {},
                          const TrainStepOptions& options = {});

// Trains only the mask head, on frozen features (PoemModelImpl::
// MaskLogitsOnFrozenFeatures): the rest of the model stays in eval mode, so its batch
// norm statistics do not move either. `optimizer` should hold the head's parameters.
TrainStepResult TrainMaskHeadStep(PoemModel& model, torch::optim::Optimizer& optimizer,
                                  const PoemBatch& batch, const PoemTargets& targets,
                                  const TrainStepOptions& options = {});

}  // namespace handlabel
