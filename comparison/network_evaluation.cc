#include "comparison/network_evaluation.h"

#include <chrono>
#include <memory>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/size_checks.h"
#include "core/stopwatch.h"
#include "hand/mesh_keypoints.h"
#include "image/line_plot.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/mask_sheet.h"

namespace handlabel {
namespace {

// A sample's crops as the network's input; every view takes part in triangulation.
HandMeshInput NetworkInput(const TrainingSample& sample) {
  HandMeshInput input;
  for (const TrainingView& v : sample.views) {
    HandMeshViewInput view;
    view.pixels = v.image;
    view.intrinsics = v.intrinsics;
    view.cam_from_master = Rigid3::FromMatrix(v.master_from_cam.topRows<3>()).Inverse();
    input.views.push_back(std::move(view));
  }
  return input;
}

// The mask grids in the row-major layout the mask metrics read (MaskIouCounts,
// MakeMaskSheet); no joints.
PoemPrediction MaskGrids(const HandMeshPrediction& prediction) {
  PoemPrediction out;
  for (const Eigen::MatrixXf& mask : prediction.masks) {
    const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows =
        mask;
    out.masks.emplace_back(rows.data(), rows.data() + rows.size());
  }
  return out;
}

}  // namespace

void NetworkEvalOptions::Check(const std::string& source) const {
  if (weights.empty()) throw InputError(source, "--weights", "a checkpoint", "");
  RequireAtLeast(source, "--frames", frames, 1);
  RequireAtLeast(source, "--batch", batch_size, 1);
  RequireAtLeast(source, "--threads", threads, 1);
  if (precision != "fp32" && precision != "bf16" && precision != "auto") {
    throw InputError(source, "--precision", "fp32, bf16 or auto", precision);
  }
  // The parts keep their own names in messages, as their fields are theirs.
  synth.Check("synth options");
  pck.Check("PckOptions");
}

NetworkEvalResult EvaluatePoemOnSynth(const HandModel& hand, const NetworkEvalOptions& o,
                                      const std::function<void(int, int)>& progress) {
  o.Check("eval-network");
  HandMeshPredictorOptions po;
  po.weights = o.weights;
  po.num_threads = o.threads;
  po.batch_size = o.batch_size;  // one forward pass per batch of samples
  po.precision = o.precision;
  const std::unique_ptr<HandMeshPredictor> predictor = CreateHandMeshPredictor(po);
  TrainingSampleOptions so;
  so.crop_size = predictor->crop_size();
  so.box_scale = o.box_scale;
  so.augment.enabled = false;
  so.augment_seed = o.synth.seed;
  so.masks = predictor->predicts_masks();
  if (!o.mask_png.empty() && !so.masks) {
    throw InputError(o.weights, "--mask-png", "weights with a mask head", "no mask head");
  }
  std::vector<TrainingSample> sheet_samples;
  std::vector<PoemPrediction> sheet_predictions;
  const SynthTrainingSamples source(hand, o.synth, so);
  if (source.num_views() != predictor->num_views()) {
    throw InputError(o.weights, "num_views",
                     std::to_string(source.num_views()) + " (the rig's views)",
                     std::to_string(predictor->num_views()));
  }
  // Every frame's errors are kept for the PCK curves: checked before allocating (10
  // million frames ended in a bare std::bad_alloc).
  RequireFitsInMemory("command line", "--frames", o.frames,
                      sizeof(double) * (21.0 + hand.num_vertices()),
                      "frames (each keeps its 21 keypoint and " +
                          std::to_string(hand.num_vertices()) + " vertex errors)");
  NetworkEvalResult r;
  r.precision = predictor->precision();
  MaskIouCounts mask_iou;
  Eigen::MatrixXd joint_errors(o.frames, 21), vertex_errors;
  for (int first = 0; first < o.frames; first += o.batch_size) {
    const std::vector<TrainingSample> samples =
        SampleRange(source, first, std::min(o.frames, first + o.batch_size));
    std::vector<HandMeshInput> inputs;
    for (const TrainingSample& s : samples) inputs.push_back(NetworkInput(s));
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<HandMeshPrediction> pred = predictor->Predict(inputs);
    r.seconds += SecondsSince(t0);
    for (size_t i = 0; i < samples.size(); ++i) {
      const int f = first + static_cast<int>(i);
      const TrainingSample& s = samples[i];
      if (vertex_errors.size() == 0) vertex_errors.resize(o.frames, s.vertices_3d.rows());
      const Points3d joints =
          ReadAnswerKeypoints(hand, pred[i].joints, pred[i].vertices, o.keypoints);
      joint_errors.row(f) = PointErrors(joints, s.joints_3d).transpose();
      vertex_errors.row(f) = PointErrors(pred[i].vertices, s.vertices_3d).transpose();
      r.pa_mpjpe_mm += 1000 * ProcrustesMeanPointError(joints, s.joints_3d);
      r.pa_mpvpe_mm += 1000 * ProcrustesMeanPointError(pred[i].vertices, s.vertices_3d);
      for (auto [how, sum] : {std::pair{AnswerKeypoints::kJoints, &r.mpjpe_joints_mm},
                              std::pair{AnswerKeypoints::kMesh, &r.mpjpe_mesh_mm},
                              std::pair{AnswerKeypoints::kMean, &r.mpjpe_mean_mm}}) {
        const Points3d read =
            ReadAnswerKeypoints(hand, pred[i].joints, pred[i].vertices, how);
        *sum += 1000 * PointErrors(read, s.joints_3d).mean();
      }
      r.true_mesh_keypoint_gap_mm +=
          1000 *
          PointErrors(KeypointsFromMeshVertices(hand, s.vertices_3d), s.joints_3d).mean();
      const PoemPrediction grids = MaskGrids(pred[i]);
      mask_iou.Add(grids, s);
      if (!o.mask_png.empty() && f < o.mask_png_frames) {
        sheet_samples.push_back(s);
        sheet_predictions.push_back(grids);
      }
    }
    r.frames += static_cast<int>(samples.size());
    if (progress) progress(r.frames, o.frames);
  }
  r.mpjpe_mm = 1000 * joint_errors.mean();
  r.mpvpe_mm = 1000 * vertex_errors.mean();
  r.pa_mpjpe_mm /= r.frames;
  r.pa_mpvpe_mm /= r.frames;
  for (double* sum : {&r.mpjpe_joints_mm, &r.mpjpe_mesh_mm, &r.mpjpe_mean_mm}) {
    *sum /= r.frames;
  }
  r.true_mesh_keypoint_gap_mm /= r.frames;
  r.joint_pck = ComputePck(joint_errors, o.pck);
  r.vertex_pck = ComputePck(vertex_errors, o.pck);
  if (so.masks) r.mask_iou = mask_iou.Iou();
  if (!o.mask_png.empty())
    WritePng(o.mask_png, MakeMaskSheet(sheet_samples, sheet_predictions));
  r.frames_per_second = r.seconds > 0 ? r.frames / r.seconds : 0;
  return r;
}

void CaptureNetworkEvalOptions::Check(const std::string& source) const {
  if (capture.empty()) throw InputError(source, "--capture", "a capture folder");
  if (weights.empty()) throw InputError(source, "--weights", "a checkpoint");
  if (out_dir.empty()) throw InputError(source, "--out", "an output folder");
  RequireAtLeast(source, "--max-frames", max_frames, 0);
  RequireAtLeast(source, "--threads", threads, 0);
  RequireAtLeast(source, "--auc-max-mm", auc_max_mm, 0);
}

CompareResult EvaluateNetworkOnCapture(const CaptureNetworkEvalOptions& o,
                                       std::ostream* log) {
  o.Check("command line");
  JobConfig base =
      CompareCaptureJob(o.capture, o.weights, o.frames, o.max_frames, o.threads, o.seed);
  base.hand_model = o.hand_model;
  base.network_keypoints = o.keypoints;
  CompareOptions compare;
  compare.out_dir = o.out_dir;
  compare.methods = {CompareMethod::kNetwork};
  compare.auc_max_mm = o.auc_max_mm;
  return RunComparison(base, compare, log);
}

namespace {

std::vector<double> Mm(std::vector<double> v) {
  for (double& x : v) x *= 1000;
  return v;
}

void WritePckCurves(const PckCurve& joints, const PckCurve* vertices,
                    const std::string& png_path, const std::string& title) {
  char jn[64], vn[64];
  std::snprintf(jn, sizeof(jn), "joints AUC %.3f", joints.auc);
  std::vector<PlotSeries> series = {
      {jn, Mm(joints.thresholds), joints.pck, PlotColor(0)}};
  if (vertices) {
    std::snprintf(vn, sizeof(vn), "vertices AUC %.3f", vertices->auc);
    series.push_back({vn, Mm(vertices->thresholds), vertices->pck, PlotColor(1)});
  }
  PlotOptions o;
  o.width = 640;
  o.height = 420;
  o.title = title;
  o.x_label = "error threshold (mm)";
  o.y_label = "PCK";
  o.y_min = 0;
  o.y_max = 1;
  WritePng(png_path, DrawLinePlot(series, o));
}

}  // namespace

void WritePckPlot(const NetworkEvalResult& r, const std::string& png_path,
                  const std::string& title) {
  WritePckCurves(r.joint_pck, &r.vertex_pck, png_path, title);
}

void WritePckPlot(const MethodScores& s, const std::string& png_path,
                  const std::string& title) {
  WritePckCurves(s.joint_pck, s.vertex_errors.cols() > 0 ? &s.vertex_pck : nullptr,
                 png_path, title);
}

}  // namespace handlabel
