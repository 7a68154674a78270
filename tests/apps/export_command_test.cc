// `handlabel export` end to end: a real label job (fallback fits on a synthetic capture
// of the open hand) whose hand model is a file in the official MANO pickle layout, then
// its labels exported and read back by independent Python readers (Debian's
// /usr/bin/python3 with numpy):
//   - tests/apps/mano_layers.py re-implements smplx's and manopth's MANO layers in
//     NumPy and feeds them the labels' parameters by the rule docs/exports.md states,
//     and the npz exports' parameters as they are: both must reproduce the labels'
//     vertices and keypoints to 1e-6 m in both conventions and both flat_hand_mean
//     settings, and the wrong guesses must not;
//   - tests/apps/export_readers.py reads the CSV with numpy and the COCO-WholeBody JSON
//     as mmpose's hand dataset does, projecting the labels itself;
//   - tests/apps/gltf_reader.py poses the .glb's skinned, morphed mesh at each keyframe
//     as a glTF 2.0 viewer does.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "capture/synth_capture.h"
#include "hand/hand_model_io.h"
#include "pipeline/hand_model_source.h"
#include "tests/apps/run_command.h"
#include "tests/hand/mano_sized_model.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::RunHandlabelCommand;

constexpr int kFrames = 3;

// One labelled capture shared by the tests (a label job takes a few seconds).
class ExportCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ScratchDir needs a running test: one folder of our own for the suite.
    std::string pattern =
        (fs::temp_directory_path() / "handlabel-export-XXXXXX").string();
    dir_ = new std::string(mkdtemp(pattern.data()));
    const std::string capture = *dir_ + "/capture";
    const HandModel open_hand = ResolveHandModel("", HandSide::kRight).model;
    SynthCaptureOptions o;
    o.rig.preset = "dexycb";
    o.rig.width = 160;
    o.rig.height = 120;
    o.num_frames = kFrames;
    o.seed = 5;
    o.num_threads = 1;
    WriteSynthCapture(open_hand, o, capture, "open hand");
    // The hand model as MANO ships it (chumpy objects, scipy sparse regressor, no
    // fingertip ids, hands_mean): what a user's MANO_RIGHT.pkl looks like.
    std::ofstream(ModelPath(), std::ios::binary) << testing::ManoStylePickle(open_hand);
    std::ofstream(JobPath()) << "name: export\nseed: 1\nhand_model: " << ModelPath()
                             << "\ninput: {format: native, path: " << capture << "}\n"
                             << "network: {threads: 2}\nrefine: {mode: always}\n"
                             << "evidence: {keypoints_2d: files, masks: none}\n"
                             << "output: {dir: " << OutDir() << ", overlays: false}\n";
    const auto r = RunHandlabelCommand({"label", "--job", JobPath(), "--quiet"});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::remove_all(*dir_, ignored);
    delete dir_;
  }

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
      ADD_FAILURE() << script << " failed (needs /usr/bin/python3 with numpy, Debian "
                    << "python3-numpy):\n"
                    << ss.str();
      return nlohmann::json::object();
    }
    std::ifstream in(report);
    return nlohmann::json::parse(in);
  }

  static std::string* dir_;
};

std::string* ExportCommand::dir_ = nullptr;

TEST_F(ExportCommand, SmplxAndManopthLayersReproduceTheLabels) {
  std::string npz_specs;
  for (const std::string convention : {"smplx", "manopth"}) {
    for (const std::string flat : {"true", "false"}) {
      const std::string out = *dir_ + "/" + convention + "_" + flat + ".npz";
      const auto r = RunHandlabelCommand({"export", "--labels", OutDir(), "--format",
                                          "npz", "--out", out, "--mano-convention",
                                          convention, "--flat-hand-mean", flat});
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_NE(r.out.find("flat_hand_mean " + flat), std::string::npos) << r.out;
      npz_specs += " --npz " + convention + ":" + flat + ":" + out;
    }
  }
  const nlohmann::json report =
      RunPython("mano_layers.py", "--model " + ModelPath() + " --labels " + OutDir() +
                                      "/labels" + npz_specs);
  ASSERT_TRUE(report.contains("cases")) << report.dump();
  EXPECT_EQ(report["labels"], kFrames);  // every label has parameters (fitted)
  int right = 0, wrong = 0;
  for (const auto& [name, errors] : report["cases"].items()) {
    if (name.rfind("WRONG", 0) == 0) {
      // A wrong convention moves the hand by far more than the tolerance.
      EXPECT_GT(errors["vertices"].get<double>(), 1e-3) << name;
      ++wrong;
      continue;
    }
    for (const char* what : {"vertices", "keypoints_3d", "joints_native"}) {
      EXPECT_LT(errors[what].get<double>(), 1e-6) << name << " " << what;
    }
    ++right;
  }
  // 2 layers x 2 flat_hand_mean settings from the labels, and the same from the 4 npz
  // files' parameters, plus their stored arrays.
  EXPECT_EQ(right, 4 + 4 + 4);
  EXPECT_EQ(wrong, 2);
}

TEST_F(ExportCommand, CsvKeypointsReadBackWithNumpy) {
  const std::string out = *dir_ + "/keypoints.csv";
  const auto r = RunHandlabelCommand(
      {"export", "--labels", OutDir() + "/labels", "--format", "csv", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report =
      RunPython("export_readers.py", "--labels " + OutDir() + "/labels --csv " + out);
  ASSERT_TRUE(report.contains("csv")) << report.dump();
  const nlohmann::json& csv = report["csv"];
  EXPECT_EQ(csv["rows"], kFrames);
  EXPECT_EQ(csv["columns"], 2 + 63);
  EXPECT_TRUE(csv["frames_in_order"].get<bool>());
  EXPECT_EQ(csv["first_columns"],
            nlohmann::json({"frame", "path", "wrist_x", "wrist_y", "wrist_z"}));
  EXPECT_LT(csv["keypoints_3d"].get<double>(), 1e-12);  // written to round-trip
}

TEST_F(ExportCommand, CocoWholeBodyHandsAreTheLabelsProjected) {
  const std::string out = *dir_ + "/coco.json";
  // No --job: the export finds the capture through output.dir/job.json.
  const auto r = RunHandlabelCommand(
      {"export", "--labels", OutDir(), "--format", "coco", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report =
      RunPython("export_readers.py", "--labels " + OutDir() + "/labels --coco " + out +
                                         " --rig " + *dir_ + "/capture/rig.json");
  ASSERT_TRUE(report.contains("coco")) << report.dump();
  const nlohmann::json& coco = report["coco"];
  EXPECT_EQ(coco["images"], kFrames * 8);               // the dexycb rig's 8 views
  EXPECT_GE(coco["hands"].get<int>(), kFrames * 6);     // the hand is in most views
  EXPECT_LT(coco["keypoints_2d"].get<double>(), 1e-6);  // pixels
  EXPECT_EQ(coco["keypoints_outside_box"], 0);
  EXPECT_TRUE(coco["image_files_exist"].get<bool>());
  EXPECT_EQ(coco["hand_keypoint_names"], 21);
}

TEST_F(ExportCommand, GlbAnimationPosesTheLabelsAsAViewerWould) {
  const std::string out = *dir_ + "/hand.glb";
  const auto r = RunHandlabelCommand(
      {"export", "--labels", OutDir(), "--format", "glb", "--out", out, "--fps", "15"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report =
      RunPython("gltf_reader.py", "--glb " + out + " --labels " + OutDir() + "/labels");
  ASSERT_TRUE(report.contains("vertices")) << report.dump();
  EXPECT_EQ(report["keyframes"], kFrames);
  EXPECT_EQ(report["morph_targets"], kFrames);
  // Skinned mesh + the keyframe's morph target = the label (float32 storage).
  EXPECT_LT(report["vertices"].get<double>(), 1e-5);
  EXPECT_LT(report["joints_native"].get<double>(), 1e-5);  // joint nodes on the joints
  EXPECT_LT(report["weight_sums"].get<double>(), 1e-6);
  // The skin alone (no pose blend shapes, 4 of 16 weights) is not the label: the
  // morph targets carry the difference.
  EXPECT_GT(report["skin_only_vertices"].get<double>(), 1e-4);
}

TEST_F(ExportCommand, BadRequestsNameWhatIsWrong) {
  const std::string out = *dir_ + "/x.npz";
  // hands_mean of another model would shift every finger: refused by name.
  const std::string other = *dir_ + "/other_right.npz";
  HandModel model = testing::RandomManoSizedModel(3);
  model.name = "other_right";
  SaveHandModel(model, other);
  auto r =
      RunHandlabelCommand({"export", "--labels", OutDir(), "--format", "npz", "--out",
                           out, "--flat-hand-mean", "false", "--hand-model", other});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("the hand model the labels were made with ('MANO_RIGHT'"),
            std::string::npos)
      << r.err;
  r = RunHandlabelCommand(
      {"export", "--labels", *dir_ + "/nowhere", "--format", "csv", "--out", out});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
  r = RunHandlabelCommand(
      {"export", "--labels", OutDir(), "--format", "fbx", "--out", out});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("npz | csv | coco | glb"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace handlabel
