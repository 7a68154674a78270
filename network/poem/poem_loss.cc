#include "network/poem/poem_loss.h"

#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "network/poem/poem_geometry.h"

namespace handlabel {
namespace {

using torch::indexing::Slice;

torch::Tensor WeightedMean(const torch::Tensor& per_item, const torch::Tensor& weights) {
  if (!weights.defined()) return per_item.mean();
  return (per_item * weights).sum() / weights.sum().clamp_min(1e-12);
}

// Backward, per-parameter clipping, optimizer step; the loss values as doubles.
TrainStepResult BackwardAndStep(PoemModel& model, torch::optim::Optimizer& optimizer,
                                const PoemLoss& loss, const TrainStepOptions& options) {
  loss.total.backward();
  if (options.grad_clip_norm > 0) {
    for (auto& p : model->parameters()) {
      if (p.grad().defined())
        torch::nn::utils::clip_grad_norm_(p, options.grad_clip_norm);
    }
  }
  optimizer.step();
  TrainStepResult result;
  result.total = loss.total.item<double>();
  for (const auto& [name, value] : loss.terms) {
    result.terms.emplace_back(name, value.item<double>());
  }
  return result;
}

}  // namespace

void PoemLossOptions::Check(const std::string& source) const {
  const std::pair<const char*, double> fields[] = {
      {"heatmap_weight", heatmap_weight},
      {"triangulation_weight", triangulation_weight},
      {"joints_weight", joints_weight},
      {"vertices_weight", vertices_weight},
      {"joints_2d_weight", joints_2d_weight},
      {"mask_weight", mask_weight}};
  for (const auto& [name, value] : fields) RequireAtLeast(source, name, value, 0);
}

PoemLoss ComputePoemLoss(const PoemOutputs& out, const PoemBatch& batch,
                         const PoemTargets& t, const torch::Tensor& regressor,
                         const PoemLossOptions& o) {
  o.Check("POEM loss options");
  const int64_t J = PoemConfig::kNumJoints;
  const double crop_w = batch.images.size(-1), crop_h = batch.images.size(-2);
  const double diag = std::sqrt(crop_w * crop_w + crop_h * crop_h);
  PoemLoss loss;

  const torch::Tensor hm = ((out.joints_2d - t.joints_2d) / diag).pow(2).sum(-1);
  const torch::Tensor heatmap = WeightedMean(hm, t.joints_2d_weights);
  const torch::Tensor tri = torch::mse_loss(out.triangulated_joints, t.joints_3d);
  torch::Tensor total = o.heatmap_weight * heatmap + o.triangulation_weight * tri;
  loss.terms = {{"heatmap_joints", heatmap}, {"triangulated_joints", tri}};

  const torch::Tensor R = regressor.to(out.layer_coords.dtype());
  const torch::Tensor gt_from_mesh = torch::matmul(R, t.vertices_3d);
  const torch::Tensor cam_from_master = torch::linalg_inv(batch.master_from_cam);
  const int64_t L = out.layer_coords.size(0);
  for (int64_t i = 0; i < L; ++i) {
    const torch::Tensor joints = out.layer_coords[i].index({Slice(), Slice(0, J)});
    const torch::Tensor verts =
        out.layer_coords[i].index({Slice(), Slice(J, torch::indexing::None)});
    const torch::Tensor j3d = torch::mse_loss(joints, t.joints_3d);
    const torch::Tensor j_mesh = torch::mse_loss(torch::matmul(R, verts), gt_from_mesh);
    const torch::Tensor v3d = torch::l1_loss(verts, t.vertices_3d);
    const torch::Tensor uv = ProjectPoints(joints, batch.intrinsics, cam_from_master);
    const torch::Tensor offset = (uv - t.joints_2d).clamp(-0.5 * diag, 0.5 * diag) / diag;
    const torch::Tensor j2d = WeightedMean(offset.pow(2).sum(-1), t.joints_2d_weights);
    const torch::Tensor recon = o.joints_weight * (j3d + j_mesh) +
                                o.vertices_weight * v3d + o.joints_2d_weight * j2d;
    total = total + recon;
    loss.terms.emplace_back("dec" + std::to_string(i) + "_recon", recon);
    if (i == L - 1) {
      loss.terms.emplace_back("joints_3d", j3d);
      loss.terms.emplace_back("joints_3d_from_mesh", j_mesh);
      loss.terms.emplace_back("vertices_3d", v3d);
      loss.terms.emplace_back("joints_2d", j2d);
    }
  }
  if (out.mask_logits.defined() && t.masks.defined()) {
    const torch::Tensor masks = PoemMaskLoss(out.mask_logits, t.masks);
    total = total + o.mask_weight * masks;
    loss.terms.emplace_back("masks", masks);
  }
  loss.total = total;
  return loss;
}

torch::Tensor PoemMaskLoss(const torch::Tensor& logits, const torch::Tensor& coverage) {
  HL_CHECK(logits.sizes() == coverage.sizes(), "mask logits and targets differ in shape");
  return torch::binary_cross_entropy_with_logits(logits, coverage.to(logits.dtype()));
}

torch::Tensor PoemKeypointRegressor(const HandModel& model) {
  const int V = model.num_vertices();
  HL_CHECK(model.joint_regressor.rows() == kNumHandJoints, "16-joint regressor expected");
  torch::Tensor native = torch::zeros({kNumHandKeypoints, V}, torch::kFloat32);
  auto acc = native.accessor<float, 2>();
  for (int r = 0; r < model.joint_regressor.outerSize(); ++r) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(
             model.joint_regressor, r);
         it; ++it) {
      acc[r][it.col()] = static_cast<float>(it.value());
    }
  }
  for (int tip = 0; tip < 5; ++tip)
    acc[kNumHandJoints + tip][model.tip_vertex_ids[tip]] = 1;
  std::vector<int64_t> order(kSnapFromNative.begin(), kSnapFromNative.end());
  return native.index_select(0, torch::tensor(order, torch::kInt64));
}

TrainStepResult TrainStep(PoemModel& model, torch::optim::Optimizer& optimizer,
                          const PoemBatch& batch, const PoemTargets& targets,
                          const torch::Tensor& regressor,
                          const PoemLossOptions& loss_options,
                          const TrainStepOptions& options) {
  model->train();
  optimizer.zero_grad();
  const PoemOutputs out = model->forward(batch);
  const PoemLoss loss = ComputePoemLoss(out, batch, targets, regressor, loss_options);
  return BackwardAndStep(model, optimizer, loss, options);
}

TrainStepResult TrainMaskHeadStep(PoemModel& model, torch::optim::Optimizer& optimizer,
                                  const PoemBatch& batch, const PoemTargets& targets,
                                  const TrainStepOptions& options) {
  HL_CHECK(model->mask_head, "TrainMaskHeadStep needs a model with a mask head");
  HL_CHECK(targets.masks.defined(), "TrainMaskHeadStep needs target masks");
  model->eval();
  model->mask_head->train();
  optimizer.zero_grad();
  PoemLoss loss;
  loss.total =
      PoemMaskLoss(model->MaskLogitsOnFrozenFeatures(batch.images), targets.masks);
  loss.terms = {{"masks", loss.total}};
  return BackwardAndStep(model, optimizer, loss, options);
}

}  // namespace handlabel
