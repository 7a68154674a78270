#pragma once
// A synthetic capture written in a dataset's real layout by
// tests/data/datasets/make_dataset_layouts.py (the official loaders' conventions:
// HO3D camera orders 1 3 2 4 0 and a random one, OakInk torch-tensor pickles, DexYCB
// apriltag entries, a second intrinsics size and a (-1, -1) keypoint). expected.json is
// what the script (numpy, as each toolkit computes) says a reader must find. Shared by
// tests/capture/dataset_layouts_test.cc and tests/pipeline/dataset_jobs_test.cc.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace testing {

struct DatasetLayout {
  std::string native;  // the synthetic capture in the native layout
  std::string root;    // the layout's root folder
  nlohmann::json expected;
};

inline const std::string kLayoutScript =
    std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/datasets/make_dataset_layouts.py";

// Renders `frames` frames with the dataset's preset rig (capsule hand, objects in the
// hand, simulated detections, seed 11) into <dir>/native and writes them in the
// dataset's layout into <dir>/<dataset> (script seed 7). Fails the test (with the
// script's output) when Debian's python3 with numpy, torch and PIL is missing:
// scripts/install-deps installs them.
inline DatasetLayout WriteDatasetLayout(const std::string& dir,
                                        const std::string& dataset, int frames = 2) {
  SynthCaptureOptions o;
  o.rig.preset = dataset;
  o.num_frames = frames;
  o.seed = 11;
  o.num_threads = 2;
  o.scene.objects = true;
  DatasetLayout layout;
  layout.native = dir + "/native";
  layout.root = dir + "/" + dataset;
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, layout.native, "capsule");
  const std::string log = dir + "/make_dataset_layouts.log";
  const std::string command = "/usr/bin/python3 " + kLayoutScript + " --capture " +
                              layout.native + " --dataset " + dataset + " --out " +
                              layout.root + " --seed 7 > " + log + " 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_EQ(status, 0) << command << "\n"
                       << ReadFileBytes(log)
                       << "\n(needs Debian's python3-numpy, python3-torch, python3-pil: "
                          "scripts/install-deps)";
  std::ifstream in(layout.root + "/expected.json");
  if (status == 0 && in) layout.expected = nlohmann::json::parse(in);
  return layout;
}

}  // namespace testing
}  // namespace handlabel
