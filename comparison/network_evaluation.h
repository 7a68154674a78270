#pragma once
// Accuracy of POEM weights (`handlabel eval-network`), two ways:
//  - on held-out synthetic frames (EvaluatePoemOnSynth): frames from the synthetic
//    generator with a chosen seed, plain crops around the true 2D keypoint box (no
//    augmentation), one forward pass per batch, and the POEM paper's metrics
//    (hand/metrics.h) on the last decoder layer in the master frame;
//  - on a capture's frames (EvaluateNetworkOnCapture, `--capture`): the labeling
//    job's network stage (its detector boxes and crops) on the capture's frames,
//    scored against the capture's truth. This is `compare`'s `network` row run alone
//    (comparison/compare_run.h): one code path, so the numbers are that row's.

#include <cstdint>
#include <functional>
#include <string>

#include "capture/synth_capture.h"
#include "comparison/compare_run.h"
#include "hand/hand_model.h"
#include "hand/mesh_keypoints.h"
#include "hand/metrics.h"
#include "training/training_samples.h"

namespace handlabel {

struct NetworkEvalOptions {
  std::string weights;        // own POEM checkpoint
  int frames = 500;           // held-out frames (>= 1)
  int batch_size = 4;         // frames per forward pass (>= 1)
  int threads = 1;            // LibTorch threads (>= 1)
  std::string precision = "fp32";  // fp32 | bf16 | auto (HandMeshPredictorOptions)
  SynthCaptureOptions synth;  // rig preset, seed, scene settings
  double box_scale = 2.0;     // crop side / keypoint box side
  PckOptions pck;             // thresholds of the PCK curve (POEM: 0-20 mm, 20 steps)
  // With a mask head: write the first mask_png_frames frames' crops with predicted and
  // true masks to this PNG (network/poem/mask_sheet.h); empty = none.
  std::string mask_png;
  int mask_png_frames = 3;
  // How the answer's keypoints are read (as a job's network.keypoints): the MPJPE,
  // PA-MPJPE and joint PCK are of these.
  AnswerKeypoints keypoints = AnswerKeypoints::kMean;
  void Check(const std::string& source) const;
};

struct NetworkEvalResult {
  int frames = 0;
  double mpjpe_mm = 0, mpvpe_mm = 0;        // mean over frames
  double pa_mpjpe_mm = 0, pa_mpvpe_mm = 0;  // Procrustes-aligned
  // MPJPE of each reading of the keypoints (hand/mesh_keypoints.h AnswerKeypoints:
  // joints, mesh, mean), and of the mesh reading of the true mesh (that reading's own
  // error, which a perfect mesh would still carry).
  double mpjpe_joints_mm = 0, mpjpe_mesh_mm = 0, mpjpe_mean_mm = 0;
  double true_mesh_keypoint_gap_mm = 0;
  PckCurve joint_pck, vertex_pck;  // thresholds in metres
  double seconds = 0;              // wall time of the forward passes
  double frames_per_second = 0;    // network only (crops excluded)
  std::string precision;           // the network's arithmetic ("auto" resolved)
  // Mask head: IoU of the predicted crop masks with the true ones (network/
  // training_sample.h MaskIouCounts, every view); -1 without a mask head.
  double mask_iou = -1;
};

// progress(done, total) after every batch.
NetworkEvalResult EvaluatePoemOnSynth(const HandModel& hand, const NetworkEvalOptions& o,
                                      const std::function<void(int, int)>& progress = {});

// `eval-network --capture`: the base job `compare --capture` builds (the same
// frames, seed, threads and hand model give the same job), run as compare's network
// row only (no other method, no ablation).
struct CaptureNetworkEvalOptions {
  std::string capture;     // native capture folder with ground truth
  std::string weights;     // network checkpoint
  std::string frames;      // 'all', 'a:b' or 'id,id,...'; empty = all
  int max_frames = 0;      // the first N of `frames`; 0 = all
  int threads = 0;         // the job's worker threads; 0 = all cores
  uint64_t seed = 0;       // the job's seed (recorded in every label)
  std::string hand_model;  // model file or 'capsule'; empty = the shipped open hand
  std::string out_dir;     // the network's label job goes to <out_dir>/methods/network
  double auc_max_mm = 0;   // PCK / AUC range; 0 = 50 for HO3D-like input, else 20
  AnswerKeypoints keypoints = AnswerKeypoints::kMean;  // the job's network.keypoints
  // Throws InputError naming the flag.
  void Check(const std::string& source) const;
};

// The comparison with the network row alone (result.methods has one entry).
CompareResult EvaluateNetworkOnCapture(const CaptureNetworkEvalOptions& options,
                                       std::ostream* log);

// PNG of the joint and vertex PCK curves (threshold in mm).
void WritePckPlot(const NetworkEvalResult& result, const std::string& png_path,
                  const std::string& title);
// The same for a scored method (vertices only where it has them).
void WritePckPlot(const MethodScores& scores, const std::string& png_path,
                  const std::string& title);

}  // namespace handlabel
