#include <unistd.h>

#include <cstdio>
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
namespace {

// The command's flags; generator settings start at SynthCaptureOptions' defaults.
struct SynthFlags {
  SynthCaptureOptions options;
  std::string out_dir, size, hand_model, side = "right", contact_sheet;
  std::string appearance = "basic";
  bool objects = false, overwrite = false, no_detections = false, no_clutter = false;
  bool sheet_crop = false;
};

// Where the capture goes, its cameras and what the frames show.
void AddRigAndSceneFlags(CLI::App& app, SynthFlags* f) {
  SynthCaptureOptions& o = f->options;
  app.add_option("--out", f->out_dir, "output folder (created)")->required();
  app.add_option("--preset", o.rig.preset,
                 "rig: dexycb (8 cams 640x480), oakink (4, 848x480), ho3d (5, 640x480), "
                 "studio (5, 1920x1080, distorted, small hands), random")
      ->capture_default_str();
  app.add_option("--frames", o.num_frames, "number of frames")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  app.add_option("--size", f->size,
                 "image size WxH (intrinsics scaled), default: the preset's");
  app.add_option("--cameras", o.rig.num_cameras, "random rig: number of cameras")
      ->capture_default_str();
  app.add_flag("--distortion", o.rig.distortion,
               "random rig: OPENCV lens distortion instead of pinhole cameras");
  app.add_flag("--objects", f->objects,
               "add objects (spheres, boxes, cylinders) held in or near the hand");
  app.add_option("--max-objects", o.scene.max_objects,
                 "most objects per frame (with --objects)")
      ->capture_default_str();
}

// Frames as one motion (capture/synth_sequence.h).
void AddSequenceFlags(CLI::App& app, SynthFlags* f) {
  SynthSequenceOptions& q = f->options.sequence;
  CLI::Option* sequence =
      app.add_flag("--sequence", q.enabled,
                   "frames form one smooth motion (reach, grasp, carry, release, "
                   "repeated) instead of independent scenes");
  app.add_option("--fps", q.fps,
                 "with --sequence: frames per second (frame f shows time f / fps; the "
                 "motion's speeds are in seconds, so the rate changes sampling only)")
      ->capture_default_str()
      ->needs(sequence);
}

// The simulated detections and the rendered images.
void AddDetectionAndImageFlags(CLI::App& app, SynthFlags* f) {
  SynthCaptureOptions& o = f->options;
  app.add_option("--detection-noise", o.detections.keypoint_sigma_px,
                 "simulated detections: keypoint noise sigma in pixels")
      ->capture_default_str();
  app.add_option("--outlier-rate", o.detections.outlier_rate,
                 "simulated detections: probability of a wild keypoint")
      ->capture_default_str();
  app.add_option("--dropout-rate", o.detections.dropout_rate,
                 "simulated detections: probability of a missing visible keypoint")
      ->capture_default_str();
  app.add_flag("--no-detections", f->no_detections, "do not write simulated detections");
  app.add_flag("--depth", o.write_depth, "also write 16-bit depth PNGs (0.1 mm units)");
  app.add_flag("--no-clutter", f->no_clutter, "plain grey backgrounds");
  app.add_option("--appearance", f->appearance,
                 "basic (the original look, what the shipped network saw) or realistic "
                 "(skin shading, forearm, table, key + fill light, camera blur and "
                 "noise: for real 2D detectors; docs/synth.md)")
      ->capture_default_str();
}

// The hand model, the run and the contact sheet.
void AddHandAndRunFlags(CLI::App& app, SynthFlags* f) {
  app.add_option("--hand-model", f->hand_model,
                 "model file or 'capsule'; default: $HANDLABEL_HAND_MODEL, then "
                 "<data dir>/models/open_hand_<side>.npz, then the open hand built "
                 "in memory");
  app.add_option("--side", f->side, "right or left hand")->capture_default_str();
  app.add_option("--threads", f->options.num_threads, "worker threads, 0 = all cores")
      ->capture_default_str();
  app.add_option(
      "--contact-sheet", f->contact_sheet,
      "also write a PNG of frame 0: all views with mask and keypoint overlays");
  app.add_flag("--contact-sheet-crop", f->sheet_crop,
               "contact sheet: show a crop around the hand in each view");
  app.add_flag("--overwrite", f->overwrite, "replace a capture already in --out");
}

// --size WxH as the rig's image size.
void SetImageSize(const std::string& size, RigPresetOptions* rig) {
  int w = 0, h = 0;
  char extra = 0;
  if (std::sscanf(size.c_str(), "%dx%d%c", &w, &h, &extra) != 2 || w <= 0 || h <= 0) {
    throw InputError("--size", "value", "WxH, e.g. 640x480", size);
  }
  rig->width = w;
  rig->height = h;
}

// The parsed flags as checked options and the hand side; throws InputError naming the
// first bad flag.
SynthCaptureOptions ToOptions(const SynthFlags& f, HandSide* side) {
  SynthCaptureOptions o = f.options;
  if (!f.size.empty()) SetImageSize(f.size, &o.rig);
  *side = ParseHandSide(f.side, "--side", "value");
  o.scene.objects = f.objects;
  o.write_detections = !f.no_detections;
  o.view.background.clutter = !f.no_clutter;
  o.view.appearance = SynthAppearanceFromName(f.appearance, "--appearance", "value");
  o.Check("synth options");
  return o;
}

void PrintSummary(const SynthCaptureSummary& s, const std::string& out_dir) {
  std::cout << "wrote " << s.frames << " frames x " << s.views / s.frames << " views to "
            << out_dir << " (" << s.views_visible << " views show the hand, "
            << s.views_occluded << " occluded, " << s.views_out_of_frame
            << " out of frame)\n";
}

void WriteContactSheet(const SynthFlags& f) {
  ContactSheetOptions sheet;
  sheet.crop_to_hand = f.sheet_crop;
  WritePng(f.contact_sheet, MakeContactSheet(CaptureReader(f.out_dir), 0, sheet));
  std::cout << "contact sheet: " << f.contact_sheet << "\n";
}

}  // namespace

int RunSynth(int argc, char** argv) {
  CLI::App app(
      "Generate a synthetic multi-view hand capture with exact ground truth, in the "
      "native capture layout (docs/capture-format.md). Frames are rendered in parallel; "
      "the output depends only on the options and --seed.\n"
      "Example: handlabel synth --preset dexycb --frames 100 --seed 1 --objects "
      "--out captures/dexycb_synth",
      "synth");
  SynthFlags flags;
  AddRigAndSceneFlags(app, &flags);
  AddSequenceFlags(app, &flags);
  AddDetectionAndImageFlags(app, &flags);
  AddHandAndRunFlags(app, &flags);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("synth", [&] {
    HandSide side = HandSide::kRight;
    const SynthCaptureOptions o = ToOptions(flags, &side);
    const ResolvedHandModel hand = ResolveHandModel(flags.hand_model, side);
    if (!hand.note.empty()) std::cerr << "handlabel synth: note: " << hand.note << "\n";
    Progress progress(o.num_frames, std::cerr, Progress::IsTerminal(STDERR_FILENO),
                      "synth");
    const SynthCaptureSummary s =
        WriteSynthCapture(hand.model, o, flags.out_dir, hand.source, flags.overwrite,
                          [&](int done, int) { progress.Update(done); });
    progress.Finish();
    PrintSummary(s, flags.out_dir);
    if (!flags.contact_sheet.empty()) WriteContactSheet(flags);
    return 0;
  });
}

}  // namespace handlabel
