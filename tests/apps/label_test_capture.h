#pragma once
// A small synthetic capture and a fitting-only job for the end-to-end labeling tests
// (8 cameras at 160x120, capsule hand, simulated detections; refine always, no masks
// so that a frame takes ~0.1 s).

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "pipeline/label_outputs.h"
#include "tests/test_util.h"

namespace handlabel::testing {

inline void WriteTestCapture(const std::string& dir, int frames, uint64_t seed) {
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 160;
  o.rig.height = 120;
  o.num_frames = frames;
  o.seed = seed;
  o.num_threads = 1;
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
}

// Writes <dir>/<name>.yaml labelling `capture` into <dir>/<output>; returns its path.
inline std::string WriteTestJob(const std::string& dir, const std::string& name,
                                const std::string& capture, const std::string& output,
                                const std::string& extra_output = "") {
  const std::string path = dir + "/" + name + ".yaml";
  std::ofstream(path) << "name: e2e\nseed: 3\nhand_model: capsule\n"
                      << "input: {format: native, path: " << capture << "}\n"
                      << "network: {threads: 2, batch_size: 2}\n"
                      << "refine: {mode: always}\n"
                      << "evidence: {keypoints_2d: files, masks: none}\n"
                      << "output: {dir: " << output << ", meshes: [ply], overlays: false"
                      << extra_output << "}\n";
  return path;
}

// Rewrites the JSON file `path` with `edit` applied.
inline void EditJson(const std::string& path,
                     const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = nlohmann::json::parse(ReadFileBytes(path));
  edit(j);
  std::ofstream(path, std::ios::trunc) << j.dump();
}

// The manifest entry of `frame` in a labelled folder (null if none).
inline nlohmann::json ManifestEntry(const std::string& out, const std::string& frame) {
  const auto manifest = nlohmann::json::parse(ReadFileBytes(ManifestPath(out)));
  for (const auto& e : manifest["frames"]) {
    if (e["frame"] == frame) return e;
  }
  return nullptr;
}

}  // namespace handlabel::testing
