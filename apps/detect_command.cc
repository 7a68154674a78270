// `handlabel detect`: MediaPipe Hands' 2D hand keypoints
// (network/detector/mediapipe_hands.h) for a capture's views, found consistently across
// the rig (pipeline/detect_capture.h), or for single images (pipeline/detect_images.h).
// docs/detector.md.

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/errors.h"
#include "core/progress.h"
#include "pipeline/detect_capture.h"
#include "pipeline/detect_images.h"

namespace handlabel {

int RunDetect(int argc, char** argv) {
  CLI::App app(
      "Detect hands with MediaPipe Hands' models (palm detection + 21 landmarks).\n"
      "Capture: handlabel detect --capture C [--model full|lite]   "
      "(C/detections/{frame}.json,\n"
      "         the hand found consistently across the rig's views)\n"
      "Images:  handlabel detect --images a.jpg b.png --out dets/   (one JSON per "
      "image)\n"
      "docs/detector.md",
      "detect");
  DetectCaptureOptions dc;
  MediapipeHandsOptions& o = dc.hands;
  std::vector<std::string> images;
  std::string out_dir, capture_dir;
  app.add_option("--capture", capture_dir, "native capture folder (multi-view)");
  app.add_flag("--overwrite", dc.overwrite,
               "with --capture: replace the detections the capture already has");
  app.add_option(
      "--overlays", dc.overlays_dir,
      "with --capture: also write DIR/<frame>/<camera>.png, each view with its "
      "palm boxes, ROI, keypoints (disc size = confidence) and the reason "
      "when there is no hand");
  app.add_flag("--second-pass", dc.multiview.second_pass,
               "with --capture: redo every view from the triangulated keypoints");
  app.add_option("--min-presence-from-3d", dc.multiview.min_presence_from_3d,
                 "with --capture: presence needed in ROIs placed from the other views")
      ->capture_default_str();
  app.add_flag("--video", dc.video,
               "with --capture: video mode, each frame's regions from the previous "
               "frame's 3D hand; palm detection where the track is lost");
  app.add_option("--palm-every", dc.palm_every,
                 "with --video: palm detection on every view of every K-th frame "
                 "(0 = only where the track is lost)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--min-palm-views", dc.multiview.min_palm_views,
                 "with --capture: views whose palms must agree")
      ->capture_default_str();
  app.add_option("--images", images, "single images (PNG or JPEG), each on its own");
  app.add_option("--out", out_dir, "with --images: output folder (created)");
  app.add_option("--model", o.model, "full or lite")->capture_default_str();
  app.add_option(
      "--model-dir", o.model_dir,
      "folder with the .tflite files (default: <data folder>/models/mediapipe)");
  app.add_option("--max-hands", o.max_hands,
                 "hands at most: per image with --images (default 2), per frame with "
                 "--capture (default 1: the hand most views confirm)");
  app.add_option("--min-palm-score", o.min_palm_score, "palm detection threshold")
      ->capture_default_str();
  std::string palm_tiles = PalmTilesText(o.palm_tiles);
  app.add_option("--palm-tiles", palm_tiles,
                 "palm detection also on N overlapping square tiles across the image's "
                 "shorter side, for small hands; off = the whole image only; auto = "
                 "4 across on images larger than 1280 px, else off")
      ->capture_default_str()
      ->check([](const std::string& text) -> std::string {
        try {
          ParsePalmTiles(text, "detect", "--palm-tiles");
          return "";
        } catch (const InputError& e) {
          return e.what();
        }
      });
  app.add_option("--min-presence", o.min_presence, "hand presence threshold")
      ->capture_default_str();
  app.add_option("--threads", dc.threads,
                 "frames (or images) detected at once, 0 = one per core")
      ->capture_default_str();
  app.add_option("--model-threads", o.num_threads,
                 "LibTorch threads of each model call (latency of one image); 1 = "
                 "parallel over frames only, best for throughput and under load")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (images.empty() == capture_dir.empty()) {
    std::cerr << "detect: give either --capture or --images (with --out)\n";
    return 2;
  }
  if (!images.empty() && out_dir.empty()) {
    std::cerr << "detect: --images needs --out\n";
    return 2;
  }
  // A flag of the other mode would be ignored (--video on images would still detect
  // every image from scratch): refused, named.
  const char* capture_only[] = {"--overwrite",
                                "--overlays",
                                "--second-pass",
                                "--video",
                                "--min-presence-from-3d",
                                "--palm-every",
                                "--min-palm-views"};
  for (const char* flag : capture_only) {
    if (!images.empty() && app.count(flag) > 0) {
      std::cerr << "detect: " << flag << " works with --capture only\n";
      return 2;
    }
  }
  if (!capture_dir.empty() && app.count("--out") > 0) {
    std::cerr << "detect: --out works with --images only (a capture's detections go to "
                 "its detections/ folder)\n";
    return 2;
  }
  if (app.count("--palm-every") > 0 && !dc.video) {
    std::cerr << "detect: --palm-every needs --video\n";
    return 2;
  }
  // Per-frame hands of a capture: 3D hands across the rig, one unless asked for more.
  dc.multiview.max_hands = app.count("--max-hands") > 0 ? o.max_hands : 1;
  if (!capture_dir.empty() && dc.video && dc.multiview.max_hands > 1) {
    std::cerr << "detect: --max-hands above 1 works without --video only (video mode "
                 "tracks one hand)\n";
    return 2;
  }
  UseOneMallocArena();
  o.palm_tiles = ParsePalmTiles(palm_tiles, "detect", "--palm-tiles");  // checked
  if (!capture_dir.empty()) {
    return RunReportingErrors("detect", [&] {
      // Made at the first frame: the capture is read under DetectCapture's writer
      // lock (an import beside it may not have listed its frames yet).
      std::unique_ptr<Progress> progress;
      const DetectCaptureSummary s =
          DetectCapture(capture_dir, dc, [&](int done, int total) {
            if (!progress) {
              progress = std::make_unique<Progress>(
                  total, std::cerr, Progress::IsTerminal(STDERR_FILENO), "detect");
            }
            progress->Update(done);
          });
      if (progress) progress->Finish();
      std::printf(
          "frames %d, hand found in %d; views with a detection %d of %d (%d from "
          "their own palm",
          s.frames, s.frames_with_hand, s.views_detected, s.views, s.views_from_palm);
      if (dc.video) {
        std::printf(", %d tracked from the previous frame; %d frames tracked",
                    s.views_tracked, s.frames_tracked);
      }
      std::printf(")");
      if (dc.multiview.max_hands > 1) {
        std::printf("; hands found %d (%d frames with more than one)", s.hands_found,
                    s.frames_with_hands);
      }
      std::printf("; %.1f s\n", s.seconds);
      if (s.worker_parks > 0) {
        std::printf(
            "other processes kept the cores busy: frames ran on fewer workers %d time(s) "
            "(docs/speed.md, \"Threads under load\")\n",
            s.worker_parks);
      }
      std::cout << "detections: " << capture_dir << "/detections\n";
      return 0;
    });
  }
  return RunReportingErrors("detect", [&] {
    dc.Check("detect");
    const MediapipeHands detector(o);
    Progress progress(static_cast<int>(images.size()), std::cerr,
                      Progress::IsTerminal(STDERR_FILENO), "detect");
    const int removed = DetectImages(detector, images, out_dir, dc.threads,
                                     [&](int done, int) { progress.Update(done); });
    progress.Finish();
    if (removed > 0) {
      std::cerr << "handlabel detect: note: removed " << removed
                << " records of an earlier run with more images (<n>.json, n >= "
                << images.size() << ")\n";
    }
    std::cout << "detections: " << out_dir << "\n";
    return 0;
  });
}

}  // namespace handlabel
