#pragma once
// One labelled capture for the `handlabel export` tests (export_command_test.cc,
// export_datasets_test.cc): a real label job (fits on a synthetic 640 x 480 capture of
// the open hand) whose hand model is a file in the official MANO pickle layout, and
// the Python readers that read the exports back (Debian's /usr/bin/python3 + numpy).

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "capture/synth_capture.h"
#include "pipeline/hand_model_source.h"
#include "tests/apps/run_command.h"
#include "tests/hand/mano_sized_model.h"
#include "tests/test_util.h"

namespace handlabel::testing {

constexpr int kExportFrames = 3;

class LabelledCaptureForExport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    namespace fs = std::filesystem;
    // ScratchDir needs a running test: one folder of our own for the suite.
    std::string pattern =
        (fs::temp_directory_path() / "handlabel-export-XXXXXX").string();
    dir_ = new std::string(mkdtemp(pattern.data()));
    const HandModel open_hand = ResolveHandModel("", HandSide::kRight).model;
    SynthCaptureOptions o;
    o.rig.preset = "dexycb";
    o.rig.width = 640;  // HO3D's calibration implies 640 x 480
    o.rig.height = 480;
    o.num_frames = kExportFrames;
    o.seed = 5;
    o.num_threads = 1;
    WriteSynthCapture(open_hand, o, CaptureDir(), "open hand");
    // The hand model as MANO ships it (chumpy objects, scipy sparse regressor, no
    // fingertip ids, hands_mean): what a user's MANO_RIGHT.pkl looks like.
    std::ofstream(ModelPath(), std::ios::binary) << ManoStylePickle(open_hand);
    std::ofstream(JobPath()) << "name: export\nseed: 1\nhand_model: " << ModelPath()
                             << "\ninput: {format: native, path: " << CaptureDir()
                             << "}\nnetwork: {threads: 2}\nrefine: {mode: always}\n"
                             << "evidence: {keypoints_2d: files, masks: none}\n"
                             << "output: {dir: " << OutDir() << ", overlays: false}\n";
    const auto r = RunHandlabelCommand({"label", "--job", JobPath(), "--quiet"});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    std::filesystem::remove_all(*dir_, ignored);
    delete dir_;
  }

  static std::string CaptureDir() { return *dir_ + "/capture"; }
  static std::string ModelPath() { return *dir_ + "/MANO_RIGHT.pkl"; }
  static std::string JobPath() { return *dir_ + "/job.yaml"; }
  static std::string OutDir() { return *dir_ + "/out"; }
  static std::string Script(const std::string& name) {
    return std::string(HANDLABEL_SOURCE_DIR) + "/tests/apps/" + name;
  }

  // Runs a Python reader; its stdout is a JSON report.
  static nlohmann::json RunPython(const std::string& script, const std::string& args) {
    const std::string report = *dir_ + "/report.json", log = *dir_ + "/python.log";
    const std::string cmd =
        "/usr/bin/python3 " + Script(script) + " " + args + " > " + report + " 2> " + log;
    if (std::system(cmd.c_str()) != 0) {
      std::ifstream in(log);
      std::stringstream ss;
      ss << in.rdbuf();
      ADD_FAILURE() << script << " failed (needs /usr/bin/python3 with numpy and yaml, "
                    << "Debian python3-numpy python3-yaml):\n"
                    << ss.str();
      return nlohmann::json::object();
    }
    std::ifstream in(report);
    return nlohmann::json::parse(in);
  }

  inline static std::string* dir_ = nullptr;
};

}  // namespace handlabel::testing
