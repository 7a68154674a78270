#include <unistd.h>

#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "capture/capture_reader.h"
#include "capture/contact_sheet.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "core/progress.h"
#include "pipeline/hand_model_source.h"

namespace handlabel {

int RunSynth(int argc, char** argv) {
  CLI::App app(
      "Generate a synthetic multi-view hand capture with exact ground truth, in the "
      "native capture layout (docs/capture-format.md). Frames are rendered in parallel; "
      "the output depends only on the options and --seed.\n"
      "Example: handlabel synth --preset dexycb --frames 100 --seed 1 --objects "
      "--out captures/dexycb_synth",
      "synth");
  SynthCaptureOptions o;
  std::string out_dir, size, hand_model, side = "right", contact_sheet;
  std::string appearance = "basic";
  bool objects = false, overwrite = false, no_detections = false, no_clutter = false;
  bool sheet_crop = false;
  app.add_option("--out", out_dir, "output folder (created)")->required();
  app.add_option(
         "--preset", o.rig.preset,
         "rig: dexycb (8 cams 640x480), oakink (4, 848x480), ho3d (5, 640x480), random")
      ->capture_default_str();
  app.add_option("--frames", o.num_frames, "number of frames")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  app.add_option("--size", size,
                 "image size WxH (intrinsics scaled), default: the preset's");
  app.add_option("--cameras", o.rig.num_cameras, "random rig: number of cameras")
      ->capture_default_str();
  app.add_flag("--distortion", o.rig.distortion,
               "random rig: OPENCV lens distortion instead of pinhole cameras");
  app.add_flag("--objects", objects,
               "add objects (spheres, boxes, cylinders) held in or near the hand");
  app.add_option("--max-objects", o.scene.max_objects,
                 "most objects per frame (with --objects)")
      ->capture_default_str();
  app.add_option("--detection-noise", o.detections.keypoint_sigma_px,
                 "simulated detections: keypoint noise sigma in pixels")
      ->capture_default_str();
  app.add_option("--outlier-rate", o.detections.outlier_rate,
                 "simulated detections: probability of a wild keypoint")
      ->capture_default_str();
  app.add_option("--dropout-rate", o.detections.dropout_rate,
                 "simulated detections: probability of a missing visible keypoint")
      ->capture_default_str();
  app.add_flag("--no-detections", no_detections, "do not write simulated detections");
  app.add_flag("--depth", o.write_depth, "also write 16-bit depth PNGs (0.1 mm units)");
  app.add_flag("--no-clutter", no_clutter, "plain grey backgrounds");
  app.add_option("--appearance", appearance,
                 "basic (the original look, what the shipped network saw) or realistic "
                 "(skin shading, forearm, table, key + fill light, camera blur and "
                 "noise: for real 2D detectors; docs/synth.md)")
      ->capture_default_str();
  app.add_option("--hand-model", hand_model,
                 "model file or 'capsule'; default: $HANDLABEL_HAND_MODEL, then "
                 "<data dir>/models/open_hand_<side>.npz, then the open hand built "
                 "in memory");
  app.add_option("--side", side, "right or left hand")->capture_default_str();
  app.add_option("--threads", o.num_threads, "worker threads, 0 = all cores")
      ->capture_default_str();
  app.add_option(
      "--contact-sheet", contact_sheet,
      "also write a PNG of frame 0: all views with mask and keypoint overlays");
  app.add_flag("--contact-sheet-crop", sheet_crop,
               "contact sheet: show a crop around the hand in each view");
  app.add_flag("--overwrite", overwrite, "replace a capture already in --out");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("synth", [&] {
    if (!size.empty()) {
      int w = 0, h = 0;
      char extra = 0;
      if (std::sscanf(size.c_str(), "%dx%d%c", &w, &h, &extra) != 2 || w <= 0 || h <= 0) {
        throw InputError("--size", "value", "WxH, e.g. 640x480", size);
      }
      o.rig.width = w;
      o.rig.height = h;
    }
    const HandSide hand_side = ParseHandSide(side, "--side", "value");
    o.scene.objects = objects;
    o.write_detections = !no_detections;
    o.view.background.clutter = !no_clutter;
    o.view.appearance = SynthAppearanceFromName(appearance, "--appearance", "value");
    o.Check();
    const ResolvedHandModel hand = ResolveHandModel(hand_model, hand_side);
    if (!hand.note.empty()) std::cerr << "handlabel synth: note: " << hand.note << "\n";
    Progress progress(o.num_frames, std::cerr, Progress::IsTerminal(STDERR_FILENO),
                      "synth");
    const SynthCaptureSummary s =
        WriteSynthCapture(hand.model, o, out_dir, hand.source, overwrite,
                          [&](int done, int) { progress.Update(done); });
    progress.Finish();
    std::cout << "wrote " << s.frames << " frames x " << s.views / s.frames
              << " views to " << out_dir << " (" << s.views_visible
              << " views show the hand, " << s.views_occluded << " occluded, "
              << s.views_out_of_frame << " out of frame)\n";
    if (!contact_sheet.empty()) {
      ContactSheetOptions sheet;
      sheet.crop_to_hand = sheet_crop;
      WritePng(contact_sheet, MakeContactSheet(CaptureReader(out_dir), 0, sheet));
      std::cout << "contact sheet: " << contact_sheet << "\n";
    }
    return 0;
  });
}

}  // namespace handlabel
