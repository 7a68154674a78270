// `handlabel eval-network`: accuracy of POEM weights on held-out synthetic frames
// (docs/training.md), or on a capture's frames through the labeling job's network stage
// (`--capture`: compare's network row alone, docs/comparison.md).

#include <stdlib.h>
#include <unistd.h>
#include <cstdio>

#include <filesystem>
#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "comparison/compare_report.h"
#include "comparison/network_evaluation.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/progress.h"
#include "core/size_checks.h"
#include "hand/hand_model_io.h"
#include "pipeline/train_config.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

struct EvalNetworkFlags {
  NetworkEvalOptions synth;
  std::string frames = "500";  // synthetic: a count; --capture: a frame list
  std::string hand_model, pck_png, capture, out, json;
  std::string keypoints = "mean";  // --keypoints
  int max_frames = 0;
  double auc_max_mm = 0;
  bool objects = false, no_clutter = false;
};

int ParseFrameCount(const std::string& text) {
  return static_cast<int>(
      ParseIntegerInRange(text, "command line", "--frames",
                          "a frame count (frame lists need --capture)", 1, 1000000000));
}

int RunOnSynth(EvalNetworkFlags& f) {
  NetworkEvalOptions& o = f.synth;
  o.frames = ParseFrameCount(f.frames);
  o.synth.scene.objects = f.objects;
  o.synth.view.background.clutter = !f.no_clutter;
  TrainConfig tc;
  tc.hand_model = f.hand_model;
  tc.source_file = "--hand-model";
  std::string hand_source;
  const HandModel hand = LoadTrainingHandModel(tc, &hand_source);
  Progress progress(o.frames, std::cerr, Progress::IsTerminal(STDERR_FILENO), "eval");
  const NetworkEvalResult r =
      EvaluatePoemOnSynth(hand, o, [&](int done, int) { progress.Update(done); });
  progress.Finish();
  std::printf(
      "frames %d (preset %s, seed %llu)\n"
      "MPJPE    %.2f mm (keypoints: %s)\nMPVPE    %.2f mm\nPA-MPJPE %.2f mm\nPA-MPVPE "
      "%.2f mm\n"
      "AUC joints (0-20 mm)   %.3f\nAUC vertices (0-20 mm) %.3f\n"
      "network %.2f frames/s (%s)\n",
      r.frames, o.synth.rig.preset.c_str(), static_cast<unsigned long long>(o.synth.seed),
      r.mpjpe_mm, ToString(o.keypoints).c_str(), r.mpvpe_mm, r.pa_mpjpe_mm, r.pa_mpvpe_mm,
      r.joint_pck.auc, r.vertex_pck.auc, r.frames_per_second, r.precision.c_str());
  std::printf(
      "MPJPE by keypoint reading (--keypoints): joints %.2f mm, mesh %.2f mm (true mesh: "
      "%.2f mm), mean %.2f mm\n",
      r.mpjpe_joints_mm, r.mpjpe_mesh_mm, r.true_mesh_keypoint_gap_mm, r.mpjpe_mean_mm);
  if (r.mask_iou >= 0) std::printf("mask IoU (crop grid)   %.3f\n", r.mask_iou);
  if (!o.mask_png.empty()) std::cout << "masks: " << o.mask_png << "\n";
  if (!f.pck_png.empty()) {
    WritePckPlot(r, f.pck_png, "PCK " + o.synth.rig.preset + " synthetic");
    std::cout << "PCK curve: " << f.pck_png << "\n";
  }
  return 0;
}

// The synthetic-frame flags mean nothing with --capture: refuse them, naming the flag.
void RefuseSynthFlags(const CLI::App& app) {
  for (const char* flag :
       {"--preset", "--batch", "--objects", "--no-clutter", "--mask-png"}) {
    if (app.count(flag) > 0) {
      throw InputError("command line", flag,
                       "no synthetic-frame flag with --capture (the capture's frames "
                       "are used)");
    }
  }
}

// A temporary folder for the label job when --out is not given; removed at the end.
class ScratchFolder {
 public:
  ScratchFolder() {
    std::string pattern = (fs::temp_directory_path() / "handlabel-eval-XXXXXX").string();
    if (!mkdtemp(pattern.data())) {
      throw Error("eval-network: cannot create a temporary folder " + pattern);
    }
    path_ = pattern;
  }
  ~ScratchFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

int RunOnCapture(const EvalNetworkFlags& f) {
  CaptureNetworkEvalOptions o;
  o.capture = f.capture;
  o.weights = f.synth.weights;
  o.frames = f.frames;
  o.max_frames = f.max_frames;
  o.threads = f.synth.threads;
  o.seed = f.synth.synth.seed;
  o.hand_model = f.hand_model;
  o.auc_max_mm = f.auc_max_mm;
  o.keypoints = f.synth.keypoints;
  std::optional<ScratchFolder> scratch;
  if (f.out.empty()) scratch.emplace();
  o.out_dir = f.out.empty() ? scratch->path() : f.out;
  const CompareResult result = EvaluateNetworkOnCapture(o, &std::cerr);
  const MethodRun& network = result.methods.at(0);
  if (!network.why_not.empty()) {
    throw InputError(o.capture, "network", "frames the network labels", network.why_not);
  }
  if (!network.has_truth) {
    throw InputError(o.capture, "ground_truth", "ground truth for the labelled frames",
                     "none");
  }
  std::cout << network.scores.frames.size() << " frames of " << result.input
            << "; errors in mm, AUC over 0-" << result.auc_max_mm << " mm\n"
            << CompareTableMarkdown(result);
  if (!f.json.empty()) {
    nlohmann::json j = {{"format", "handlabel-eval-network"},
                        {"version", 1},
                        {"input", result.input},
                        {"frames", result.frames},
                        {"auc_range_mm", {0.0, result.auc_max_mm}},
                        {"method", MethodJson(network)}};
    if (scratch) j["method"].erase("output_dir");  // removed below
    WriteFileAtomically(f.json, j.dump(1) + "\n");
    std::cout << "json: " << f.json << "\n";
  }
  if (!f.pck_png.empty()) {
    WritePckPlot(network.scores, f.pck_png, "PCK " + result.input);
    std::cout << "PCK curve: " << f.pck_png << "\n";
  }
  if (!f.out.empty()) std::cout << "labels: " << network.output_dir << "\n";
  return 0;
}

}  // namespace

int RunEvalNetwork(int argc, char** argv) {
  CLI::App app(
      "Evaluate POEM weights on held-out synthetic frames (crops around the true 2D "
      "keypoint box): MPJPE, MPVPE, PA-MPJPE, PA-MPVPE, AUC of the PCK curve (0-20 mm), "
      "and a PCK curve PNG; or, with --capture, on a capture's frames through the "
      "labeling job's network stage: compare's network row (MPVPE, RR-V, PA-V, AUC-V, "
      "MPJPE, RR-J, PA-J, AUC-J).\n"
      "Examples: handlabel eval-network --weights models/poem_small_dexycb.pt --preset "
      "dexycb --frames 500 --seed 9401 --objects --pck-png pck.png\n"
      "          handlabel eval-network --weights models/poem_small_dexycb.pt --capture "
      "captures/dex50 --frames 0:10 --json eval.json",
      "eval-network");
  EvalNetworkFlags f;
  NetworkEvalOptions& o = f.synth;
  o.synth.seed = 777;
  app.add_option("--weights", o.weights, "own POEM checkpoint (.pt)")->required();
  app.add_option("--capture", f.capture,
                 "a native capture with ground truth: evaluate on its frames as "
                 "compare's network row does");
  app.add_option("--preset", o.synth.rig.preset, "rig preset (the network's view count)")
      ->capture_default_str();
  app.add_option("--frames", f.frames,
                 "synthetic: held-out frames (a count); --capture: 'all', 'a:b' or "
                 "'id,id,...'")
      ->capture_default_str();
  app.add_option("--max-frames", f.max_frames, "--capture: the first N frames")
      ->capture_default_str();
  app.add_option("--seed", o.synth.seed,
                 "seed of the held-out frames (use one the training never saw); "
                 "--capture: the label job's seed (default 0, as compare's)")
      ->capture_default_str();
  app.add_option("--batch", o.batch_size, "frames per forward pass")
      ->capture_default_str();
  app.add_option("--threads", o.threads,
                 "LibTorch threads; --capture: the job's threads (0 = all cores)")
      ->capture_default_str();
  app.add_option("--precision", o.precision,
                 "synthetic: arithmetic of the network's products: fp32, bf16 or auto "
                 "(bf16 where the CPU has a bf16 unit; docs/speed.md)")
      ->check(CLI::IsMember({"fp32", "bf16", "auto"}))
      ->capture_default_str();
  app.add_flag("--objects", f.objects, "objects held in or near the hand");
  app.add_flag("--no-clutter", f.no_clutter, "plain grey backgrounds");
  app.add_option("--hand-model", f.hand_model,
                 "hand model the network was trained with (default: the shipped open "
                 "hand)");
  app.add_option("--keypoints", f.keypoints,
                 "how the answer's keypoints are read, as a job's network.keypoints: "
                 "joints (the network's joint outputs), mesh (read off its mesh), mean "
                 "(of the two)")
      ->check([](const std::string& name) {
        return AnswerKeypointsNamed(name) ? "" : "expected " + AnswerKeypointsChoices();
      })
      ->capture_default_str();
  app.add_option("--pck-png", f.pck_png, "write the PCK curves to this PNG");
  app.add_option(
      "--mask-png", o.mask_png,
      "networks with a mask head: write the first frames' crops with predicted "
      "(red) and true (green outline) masks to this PNG");
  app.add_option("--out", f.out,
                 "--capture: keep the network's label job in DIR/methods/network "
                 "(default: a temporary folder, removed)");
  app.add_option("--json", f.json, "--capture: write the row (compare.json's form) here");
  app.add_option("--auc-max-mm", f.auc_max_mm,
                 "--capture: PCK / AUC range 0..this (mm); 0 = 50 for HO3D input, else "
                 "20")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("eval-network", [&] {
    o.keypoints = *AnswerKeypointsNamed(f.keypoints);  // the check above passed
    if (f.capture.empty()) {
      for (const char* flag : {"--max-frames", "--out", "--json", "--auc-max-mm"}) {
        if (app.count(flag) > 0) {
          throw InputError("command line", flag, "--capture (a capture-only flag)");
        }
      }
      return RunOnSynth(f);
    }
    RefuseSynthFlags(app);
    // Defaults as compare --capture's: every frame, seed 0, all cores.
    if (app.count("--frames") == 0) f.frames.clear();
    if (app.count("--seed") == 0) o.synth.seed = 0;
    if (app.count("--threads") == 0) o.threads = 0;
    return RunOnCapture(f);
  });
}

}  // namespace handlabel
