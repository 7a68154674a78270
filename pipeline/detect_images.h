#pragma once
// `handlabel detect --images`: MediaPipe Hands (network/detector/mediapipe_hands.h) on
// single images, one JSON file per image with everything the pipeline computes (palms,
// ROIs, landmarks in image, crop and world coordinates, presence, handedness) and the
// time of each step; the parity check against MediaPipe's own runtime
// (scripts/mediapipe-parity) and the real-photo benchmark read these files.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "network/detector/mediapipe_hands.h"

namespace handlabel {

// The JSON record of one image: {"image", "width", "height", "palms": [...],
// "hands": [...], "time_ms": {...}} (docs/detector.md, "Single images").
// Times in milliseconds: reading the file (`read_ms`) and the trace's steps.
nlohmann::json DetectionRecordJson(const std::string& image_path, const ImageU8& rgb,
                                   const MediapipeTrace& trace,
                                   const std::vector<HandDetection>& hands,
                                   double read_ms);

// Runs the detector on each image and writes <out_dir>/<index>.json (index = position in
// `images`) and <out_dir>/summary.json (per-image times and hand counts, means).
// `threads` images at once (0 = one per core); `on_image(done, total)` after each
// image, one call at a time. Throws InputError naming an unreadable image, or naming
// the holder when another process writes into `out_dir` (core/file_lock.h).
// Records <n>.json of an earlier run with more images (n >= images.size()) are removed
// at the end, so the folder describes this run only; files that are not such records
// (by name and content) are never touched. Returns how many were removed.
int DetectImages(const MediapipeHands& detector, const std::vector<std::string>& images,
                 const std::string& out_dir, int threads = 0,
                 const std::function<void(int, int)>& on_image = nullptr);

// An image as 3-channel RGB (gray is repeated, alpha dropped).
ImageU8 ToRgb(const ImageU8& image);

}  // namespace handlabel
