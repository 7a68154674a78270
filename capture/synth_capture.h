#pragma once
// Synthetic multi-view hand captures with exact ground truth (like COLMAP's synthetic
// dataset module): library code used by tests, training, benchmarks and
// `handlabel synth`.
//
// SynthGenerator makes frames in memory; WriteSynthCapture writes a capture folder in
// the native layout (capture_format.h, docs/capture-format.md), in parallel over frames
// with TBB. Frame f depends only on (seed, f): the output is byte-identical for any
// thread count, and different seeds give different scenes. With sequence.enabled the
// frames are moments of one motion (capture/synth_sequence.h), still each made alone.

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/rig_presets.h"
#include "capture/synth_detections.h"
#include "capture/synth_scene.h"
#include "capture/synth_sequence.h"
#include "capture/synth_view.h"
#include "geometry/rig.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_model.h"
#include "image/image.h"
#include "image/rasterizer.h"

namespace handlabel {

struct SynthCaptureOptions {
  RigPresetOptions rig;              // which cameras
  SynthSceneOptions scene;           // poses, shapes, objects
  SynthSequenceOptions sequence;     // frames as one motion (off: independent frames)
  SynthViewOptions view;             // backgrounds, visibility, the look (appearance)
  DetectionNoiseOptions detections;  // simulated detector
  int num_frames = 10;               // >= 1
  uint64_t seed = 0;                 // everything random derives from it
  bool write_depth = false;          // depth/{camera}/{frame}.png (16-bit)
  bool write_detections = true;      // detections/ (keypoints + noisy masks)
  int num_threads = 0;               // 0 = TBB's default (all cores)
  PngWriteOptions png;
  void Check(const std::string& source) const;
};

// One generated frame.
struct SynthFrame {
  int index = 0;
  SynthScene scene;
  std::vector<SynthView> views;            // rig order
  std::vector<ViewDetections> detections;  // rig order; empty if not requested
};

class SynthGenerator {
 public:
  // Precomputes the anatomy and every camera's pixel rays. Throws InputError for bad
  // options or a model the anatomy cannot use.
  SynthGenerator(const HandModel& model, Rig rig, const SynthCaptureOptions& options);
  const Rig& rig() const { return rig_; }
  const HandModel& model() const { return model_; }
  const SynthCaptureOptions& options() const { return options_; }
  // Deterministic in (options.seed, index); thread-safe.
  SynthFrame Generate(int index) const;

 private:
  void CheckPhotoBackgrounds() const;

  HandModel model_;
  Rig rig_;
  SynthCaptureOptions options_;
  HandAnatomy anatomy_;
  HandLimits limits_;
  std::vector<PixelRays> rays_;
};

struct SynthCaptureSummary {
  int frames = 0;
  int views = 0;
  int views_visible = 0;       // status "visible"
  int views_occluded = 0;      // status "occluded"
  int views_out_of_frame = 0;  // status "out_of_frame"
  double seconds = 0;
};

// Writes a capture into `out_dir` (created; must not already hold a capture unless
// `overwrite`). `hand_model_source` is recorded in the manifest. `progress(done,
// total)` is called after each frame, from worker threads, serialised.
SynthCaptureSummary WriteSynthCapture(
    const HandModel& model, const SynthCaptureOptions& options,
    const std::string& out_dir, const std::string& hand_model_source,
    bool overwrite = false, const std::function<void(int, int)>& progress = nullptr);

// The generator settings as JSON (recorded in the manifest).
nlohmann::json SynthOptionsToJson(const SynthCaptureOptions& options);

}  // namespace handlabel
