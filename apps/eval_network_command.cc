// `handlabel eval-network`: accuracy of POEM weights on held-out synthetic frames
// (docs/training.md).

#include <unistd.h>
#include <cstdio>

#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/errors.h"
#include "core/hand_model_io.h"
#include "core/progress.h"
#include "pipeline/network_evaluation.h"
#include "pipeline/train_config.h"

namespace handlabel {

int RunEvalNetwork(int argc, char** argv) {
  CLI::App app(
      "Evaluate POEM weights on held-out synthetic frames (crops around the true 2D "
      "keypoint box): MPJPE, MPVPE, PA-MPJPE, PA-MPVPE, AUC of the PCK curve (0-20 mm), "
      "and a PCK curve PNG.\n"
      "Example: handlabel eval-network --weights models/poem_small_dexycb.pt --preset "
      "dexycb --frames 500 --seed 777 --pck-png pck.png",
      "eval-network");
  NetworkEvalOptions o;
  o.synth.seed = 777;
  std::string pck_png, hand_model;
  bool objects = false, no_clutter = false;
  app.add_option("--weights", o.weights, "own POEM checkpoint (.pt)")->required();
  app.add_option("--preset", o.synth.rig.preset, "rig preset (the network's view count)")
      ->capture_default_str();
  app.add_option("--frames", o.frames, "held-out frames")->capture_default_str();
  app.add_option("--seed", o.synth.seed,
                 "seed of the held-out frames (use one the training never saw)")
      ->capture_default_str();
  app.add_option("--batch", o.batch_size, "frames per forward pass")
      ->capture_default_str();
  app.add_option("--threads", o.threads, "LibTorch threads")->capture_default_str();
  app.add_flag("--objects", objects, "objects held in or near the hand");
  app.add_flag("--no-clutter", no_clutter, "plain grey backgrounds");
  app.add_option("--hand-model", hand_model,
                 "hand model the network was trained with (default: the shipped open "
                 "hand)");
  app.add_option("--pck-png", pck_png, "write the PCK curves to this PNG");
  app.add_option(
      "--mask-png", o.mask_png,
      "networks with a mask head: write the first frames' crops with predicted "
      "(red) and true (green outline) masks to this PNG");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("eval-network", [&] {
    o.synth.scene.objects = objects;
    o.synth.view.background.clutter = !no_clutter;
    TrainConfig tc;
    tc.hand_model = hand_model;
    tc.source_file = "--hand-model";
    std::string hand_source;
    const HandModel hand = LoadTrainingHandModel(tc, &hand_source);
    Progress progress(o.frames, std::cerr, Progress::IsTerminal(STDERR_FILENO), "eval");
    const NetworkEvalResult r =
        EvaluatePoemOnSynth(hand, o, [&](int done, int) { progress.Update(done); });
    progress.Finish();
    std::printf(
        "frames %d (preset %s, seed %llu)\n"
        "MPJPE    %.2f mm\nMPVPE    %.2f mm\nPA-MPJPE %.2f mm\nPA-MPVPE %.2f mm\n"
        "AUC joints (0-20 mm)   %.3f\nAUC vertices (0-20 mm) %.3f\n"
        "network %.2f frames/s\n",
        r.frames, o.synth.rig.preset.c_str(),
        static_cast<unsigned long long>(o.synth.seed), r.mpjpe_mm, r.mpvpe_mm,
        r.pa_mpjpe_mm, r.pa_mpvpe_mm, r.joint_pck.auc, r.vertex_pck.auc,
        r.frames_per_second);
    std::printf("MPJPE of keypoints read off the mesh %.2f mm (true mesh: %.2f mm)\n",
                r.mpjpe_from_mesh_mm, r.true_mesh_keypoint_gap_mm);
    if (r.mask_iou >= 0) std::printf("mask IoU (crop grid)   %.3f\n", r.mask_iou);
    if (!o.mask_png.empty()) std::cout << "masks: " << o.mask_png << "\n";
    if (!pck_png.empty()) {
      WritePckPlot(r, pck_png, "PCK " + o.synth.rig.preset + " synthetic");
      std::cout << "PCK curve: " << pck_png << "\n";
    }
    return 0;
  });
}

}  // namespace handlabel
