#include <unistd.h>

#include <iostream>
#include <sstream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/errors.h"
#include "fitting/ceres_hand_fitter.h"
#include "pipeline/fit_capture.h"

namespace handlabel {
namespace {

// A fitter setting given on the command line becomes a job field (fit.*); one left
// out stays unset, so the job equals a YAML job without that field.
template <typename T>
void SetIfGiven(const CLI::App& app, const char* flag, const T& value,
                std::optional<T>* field) {
  if (app.count(flag) > 0) *field = value;
}

void PrintSummary(const FitCaptureSummary& s) {
  if (!s.hand_model_note.empty())
    std::cerr << "handlabel fit: note: " << s.hand_model_note << "\n";
  std::cout << "fitted " << s.frames << " frames (" << s.converged << " converged, "
            << s.job.failed << " failed), " << s.mean_seconds << " s per frame";
  if (s.has_ground_truth) {
    std::cout << "; MPJPE " << 1000 * s.mpjpe << " mm, MPVPE " << 1000 * s.mpvpe
              << " mm, PA-MPJPE " << 1000 * s.pa_mpjpe << " mm, AUC(0-20 mm) "
              << s.auc_joints;
  }
  std::cout << "; largest joint-limit violation " << s.max_limit_violation_deg
            << " deg\nsummary: " << s.summary_path << "\n";
}

// The command's flags; fitter settings start at the fitter's defaults (for --help).
struct FitFlags {
  FitCaptureOptions options;
  std::string frames, ignore, loss = "cauchy";
  double loss_scale = HandFitOptions().keypoint_loss.scale;
  double keypoint_sigma = HandFitOptions().keypoint_sigma_px;
  double silhouette_sigma = HandFitOptions().silhouette_sigma_px;
  int silhouette_rounds = HandFitOptions().silhouette_rounds;
  double mask_margin = HandFitOptions().mask_margin_max_px;
  int pca = HandFitConfig().pose_pca_comps;
  std::string unknown_occluders = "two_sided";
  bool no_silhouettes = false, no_limits = false, fixed_shape = false;
  bool no_silhouette_check = false;
};

void AddEvidenceFlags(CLI::App& app, FitFlags* f) {
  FitCaptureOptions& o = f->options;
  app.add_option("--capture", o.capture_dir, "capture folder (native layout)")
      ->required();
  app.add_option("--out", o.out_dir, "output folder (created)")->required();
  app.add_option("--frames", f->frames, "comma-separated frame ids (default: all)");
  app.add_option("--ignore-views", f->ignore,
                 "comma-separated camera names whose keypoints and masks are ignored");
  app.add_option("--max-frames", o.max_frames, "fit only the first N chosen frames")
      ->capture_default_str();
  app.add_option("--init", o.fit.init,
                 "triangulate | gt | previous | FOLDER of <frame>.json parameter files "
                 "(or a job's labels)")
      ->capture_default_str();
  app.add_option("--evidence", o.evidence,
                 "2D keypoints: auto | detections | keypoints (exact projections)")
      ->capture_default_str();
  app.add_option("--object-masks", o.object_masks,
                 "object masks as occluders (pixels behind objects do not count against "
                 "the silhouettes): files | none")
      ->capture_default_str();
  app.add_option("--masks", o.masks, "masks: auto | detections | truth | none")
      ->capture_default_str();
  app.add_flag("--no-silhouettes", f->no_silhouettes, "ignore masks (as --masks none)");
}

void AddFitterFlags(CLI::App& app, FitFlags* f) {
  app.add_option("--loss", f->loss, "robust keypoint loss: cauchy | huber | trivial")
      ->capture_default_str();
  app.add_option("--loss-scale", f->loss_scale,
                 "robust loss scale, in units of --keypoint-sigma")
      ->capture_default_str();
  app.add_option("--keypoint-sigma", f->keypoint_sigma, "keypoint error scale in pixels")
      ->capture_default_str();
  app.add_option("--silhouette-sigma", f->silhouette_sigma,
                 "silhouette error scale in pixels")
      ->capture_default_str();
  app.add_option("--silhouette-rounds", f->silhouette_rounds,
                 "outline re-matching rounds with silhouettes (0 = keypoints only)")
      ->capture_default_str();
  app.add_option("--mask-margin", f->mask_margin,
                 "largest per-view mask margin (masks uniformly too fat or too thin) "
                 "estimated and taken out, pixels; 0 = off")
      ->capture_default_str();
  app.add_option("--pca", f->pca,
                 "pose as PCA coefficients: 0 (45 axis-angle values), 12 or 45")
      ->capture_default_str();
  app.add_option("--unknown-occluders", f->unknown_occluders,
                 "silhouettes without object masks (--object-masks none): two_sided "
                 "(guarded by the silhouette check) | one_sided (only observed hand "
                 "pixels must be covered)")
      ->capture_default_str();
  app.add_flag(
      "--no-silhouette-check", f->no_silhouette_check,
      "keep a silhouette fit even when it disagrees with the keypoints-only fit");
  app.add_flag("--no-limits", f->no_limits, "no anatomical joint limits");
  app.add_flag("--fixed-shape", f->fixed_shape, "keep betas at their initial values");
}

void AddRunFlags(CLI::App& app, FitFlags* f) {
  FitCaptureOptions& o = f->options;
  app.add_option("--hand-model", o.hand_model,
                 "model file or 'capsule'; default: $HANDLABEL_HAND_MODEL, then "
                 "<data dir>/models/open_hand_<side>.npz, then the open hand built "
                 "in memory");
  app.add_flag("--overlay", o.overlays,
               "also write the label job's overlay pictures: every view of every frame "
               "with the fitted mesh and keypoints, <out>/overlays/<frame>/<camera>.jpg");
  app.add_option("--threads", o.num_threads, "frames in parallel, 0 = all cores")
      ->capture_default_str();
}

// The parsed flags as options; fitter flags that were not given stay unset.
FitCaptureOptions ToOptions(const CLI::App& app, const FitFlags& f) {
  FitCaptureOptions o = f.options;
  o.frames = SplitCommas(f.frames);
  o.ignore_views = SplitCommas(f.ignore);
  RobustLossFromName(f.loss, "--loss");  // names the flag when the loss is unknown
  SetIfGiven(app, "--loss", f.loss, &o.fit.keypoint_loss);
  SetIfGiven(app, "--loss-scale", f.loss_scale, &o.fit.keypoint_loss_scale);
  SetIfGiven(app, "--keypoint-sigma", f.keypoint_sigma, &o.fit.keypoint_sigma_px);
  SetIfGiven(app, "--silhouette-sigma", f.silhouette_sigma, &o.fit.silhouette_sigma_px);
  SetIfGiven(app, "--silhouette-rounds", f.silhouette_rounds, &o.fit.silhouette_rounds);
  SetIfGiven(app, "--mask-margin", f.mask_margin, &o.fit.mask_margin_px);
  SetIfGiven(app, "--pca", f.pca, &o.fit.pose_pca_comps);
  if (f.unknown_occluders != "one_sided" && f.unknown_occluders != "two_sided") {
    throw InputError("command line", "--unknown-occluders", "one_sided | two_sided",
                     f.unknown_occluders);
  }
  SetIfGiven(app, "--unknown-occluders", f.unknown_occluders, &o.fit.unknown_occluders);
  if (f.no_silhouette_check) o.fit.silhouette_check = false;
  if (f.no_limits) o.fit.joint_limits = false;
  if (f.fixed_shape) o.fit.optimise_shape = false;
  if (f.no_silhouettes) o.masks = "none";
  return o;
}

}  // namespace

int RunFit(int argc, char** argv) {
  CLI::App app(
      "Fit the hand model with Ceres to every frame of a capture (native layout) from "
      "its 2D keypoints and masks, with anatomical limits and priors; the paper's "
      "\"Multi-view Fit.\" baseline with --init triangulate. Runs as a labeling job "
      "without a network (the same labels as 'handlabel label' with the matching job "
      "fields) and writes labels and a summary with errors against ground truth when "
      "the capture has it (docs/fitting.md).\n"
      "Example: handlabel fit --capture captures/dexycb_synth --max-frames 50 "
      "--out fits/dexycb",
      "fit");
  FitFlags flags;
  AddEvidenceFlags(app, &flags);
  AddFitterFlags(app, &flags);
  AddRunFlags(app, &flags);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("fit", [&] {
    const FitCaptureSummary s = FitCapture(ToOptions(app, flags), &std::cerr);
    PrintSummary(s);
    return s.job.failed > 0 && s.job.ok == 0 ? 1 : 0;
  });
}

}  // namespace handlabel
