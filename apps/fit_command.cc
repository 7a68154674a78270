#include <iostream>
#include <sstream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/errors.h"
#include "capture/capture_reader.h"
#include "pipeline/fit_capture.h"
#include "pipeline/hand_model_source.h"

namespace handlabel {

int RunFit(int argc, char** argv) {
  CLI::App app(
      "Fit the hand model with Ceres to every frame of a capture (native layout) from "
      "its 2D keypoints and masks, with anatomical limits and priors; the paper's "
      "\"Multi-view Fit.\" baseline with --init triangulate. Writes per-frame results "
      "and a summary with errors against ground truth when the capture has it "
      "(docs/fitting.md).\n"
      "Example: handlabel fit --capture captures/dexycb_synth --max-frames 50 "
      "--out fits/dexycb",
      "fit");
  FitCaptureOptions o;
  std::string frames, ignore, hand_model, loss = "cauchy";
  bool no_silhouettes = false, no_limits = false, fixed_shape = false;
  app.add_option("--capture", o.capture_dir, "capture folder (native layout)")
      ->required();
  app.add_option("--out", o.out_dir, "output folder (created)")->required();
  app.add_option("--frames", frames, "comma-separated frame ids (default: all)");
  app.add_option("--ignore-views", ignore,
                 "comma-separated camera names whose keypoints and masks are ignored");
  app.add_option("--max-frames", o.max_frames, "fit only the first N chosen frames")
      ->capture_default_str();
  app.add_option("--init", o.init,
                 "triangulate | gt | previous | FOLDER of <frame>.json parameter files")
      ->capture_default_str();
  app.add_option("--evidence", o.evidence,
                 "2D keypoints: auto | detections | keypoints (exact projections)")
      ->capture_default_str();
  app.add_option("--masks", o.masks, "masks: auto | detections | truth | none")
      ->capture_default_str();
  app.add_option("--loss", loss, "robust keypoint loss: cauchy | huber | trivial")
      ->capture_default_str();
  app.add_option("--loss-scale", o.fit.keypoint_loss.scale,
                 "robust loss scale, in units of --keypoint-sigma")
      ->capture_default_str();
  app.add_option("--keypoint-sigma", o.fit.keypoint_sigma_px,
                 "keypoint error scale in pixels")
      ->capture_default_str();
  app.add_option("--silhouette-sigma", o.fit.silhouette_sigma_px,
                 "silhouette error scale in pixels")
      ->capture_default_str();
  app.add_option("--silhouette-rounds", o.fit.silhouette_rounds,
                 "outline re-matching rounds with silhouettes (0 = keypoints only)")
      ->capture_default_str();
  app.add_option("--pca", o.config.pose_pca_comps,
                 "pose as PCA coefficients: 0 (45 axis-angle values), 12 or 45")
      ->capture_default_str();
  app.add_flag("--no-silhouettes", no_silhouettes, "ignore masks");
  app.add_flag("--no-limits", no_limits, "no anatomical joint limits");
  app.add_flag("--fixed-shape", fixed_shape, "keep betas at their initial values");
  app.add_option("--hand-model", hand_model,
                 "model file or 'capsule'; default: $HANDLABEL_HAND_MODEL, then "
                 "<data dir>/models/open_hand_<side>.npz, then the open hand built in memory");
  app.add_option("--overlay", o.overlay_png,
                 "also write a PNG of the first fitted frame: every view with the fitted "
                 "silhouette, keypoints and the 2D evidence");
  app.add_option("--threads", o.num_threads, "frames in parallel, 0 = all cores")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("fit", [&] {
    std::stringstream list(frames);
    for (std::string id; std::getline(list, id, ',');) {
      if (!id.empty()) o.frames.push_back(id);
    }
    std::stringstream names(ignore);
    for (std::string name; std::getline(names, name, ',');) {
      if (!name.empty()) o.ignore_views.push_back(name);
    }
    o.fit.keypoint_loss.type = RobustLossFromName(loss, "--loss");
    o.config.use_silhouettes = !no_silhouettes;
    o.config.use_joint_limits = !no_limits;
    o.config.optimise_shape = !fixed_shape;
    o.Check();
    const CaptureReader capture(o.capture_dir);
    const HandSide side =
        capture.manifest().hand_side == "left" ? HandSide::kLeft : HandSide::kRight;
    const ResolvedHandModel hand = ResolveHandModel(hand_model, side);
    if (!hand.note.empty()) std::cerr << "handlabel fit: note: " << hand.note << "\n";
    const FitCaptureSummary s = FitCapture(o, hand.model);
    std::cout << "fitted " << s.frames << " frames (" << s.converged << " converged), "
              << s.mean_seconds << " s per frame";
    if (s.has_ground_truth) {
      std::cout << "; MPJPE " << 1000 * s.mpjpe << " mm, MPVPE " << 1000 * s.mpvpe
                << " mm, PA-MPJPE " << 1000 * s.pa_mpjpe << " mm, AUC(0-20 mm) "
                << s.auc_joints;
    }
    std::cout << "\nsummary: " << s.summary_path << "\n";
    return 0;
  });
}

}  // namespace handlabel
