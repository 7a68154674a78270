// `handlabel adapt`: the pseudo-label loop on the user's own capture (pipeline/adapt.h,
// docs/adapt.md).

#include <iostream>
#include <string>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "pipeline/adapt.h"

namespace handlabel {

int RunAdapt(int argc, char** argv) {
  CLI::App app(
      "Teach the network your own rig: detect hands, fit labels, fine-tune the network "
      "on the labels that agree with their detections (a block of frames held out to "
      "measure it), then label the capture with network + quality checks + fallback "
      "fit. Every stage is kept in the output folder; the same command continues a "
      "killed run (docs/adapt.md).\n"
      "Example: handlabel adapt --capture captures/mine --out adapted/mine --budget 60",
      "adapt");
  AdaptOptions o;
  app.add_option("--capture", o.capture_dir, "a native capture (capture import)")
      ->required();
  app.add_option("--out", o.out_dir,
                 "output folder: network.pt, model_card.md, labels/ and every stage's "
                 "files")
      ->required();
  app.add_option("--budget", o.budget_minutes,
                 "minutes for all stages; training gets what the others leave "
                 "(default 60)");
  app.add_option("--threads", o.threads, "threads (default 2)");
  app.add_option("--weights", o.weights,
                 "weights to start from (default: the shipped "
                 "models/poem_small_dexycb.pt)");
  app.add_option("--heldout", o.heldout,
                 "frames that never train and measure the result: 'a:b' (positions in "
                 "the sorted frames, b excluded) or 'id,id,...' (default: the last 16 "
                 "when the capture has >= 40 frames, the 4 before them left out)");
  app.add_option("--label-min-views", o.selection.min_views,
                 "a fit label trains only if at least this many views fit its 2D "
                 "within --label-max-rms-px (default 3)");
  app.add_option("--label-max-rms-px", o.selection.max_view_rms_px,
                 "... within this RMS pixel distance (default 10)");
  app.add_option("--learning-rate", o.learning_rate, "peak learning rate (default 1e-4)");
  app.add_option("--accept-mm", o.accept_mm,
                 "the label stage's check thresholds are chosen on the held-out "
                 "answers: one farther than this from its fit label is bad (default "
                 "10)");
  app.add_option("--synth-share", o.synth_share,
                 "share of training samples that are synthetic hands rendered with the "
                 "capture's cameras over its own backgrounds, with exact targets "
                 "(0..1, default 0: the capture's frames only; docs/adapt.md)");
  app.add_option("--seed", o.seed, "training order, augmentation and torch seeds");
  bool no_overlays = false;
  app.add_flag("--no-overlays", no_overlays,
               "no overlay pictures of the held-out and final labels");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  o.overlays = !no_overlays;
  return RunReportingErrors("adapt", [&] {
    const AdaptSummary s = RunAdaptation(o, &std::cerr);
    std::cout << "network " << s.network_path << "\nlabels " << s.labels_dir
              << "\nmodel card " << o.out_dir << "/model_card.md\n";
    return 0;
  });
}

}  // namespace handlabel
