// `handlabel export` end to end: the labels of tests/apps/export_fixture.h's label job
// exported and read back by independent Python readers (Debian's
// /usr/bin/python3 with numpy):
//   - tests/apps/mano_layers.py re-implements smplx's, manopth's and manotorch's MANO
//     layers in NumPy and feeds them the labels' parameters by the rules
//     docs/exports.md states, and the npz exports' parameters as they are: all must
//     reproduce the labels' vertices and keypoints to 1e-6 m in every convention and
//     both flat_hand_mean settings, and the wrong guesses must not;
//   - tests/apps/export_readers.py reads the CSV with numpy and the COCO-WholeBody JSON
//     as mmpose's hand dataset does, projecting the labels itself;
//   - tests/apps/gltf_reader.py poses the .glb's skinned, morphed mesh at each keyframe
//     as a glTF 2.0 viewer does.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hand/hand_model_io.h"
#include "tests/apps/export_fixture.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::kExportFrames;
using testing::RunHandlabelCommand;

using ExportCommand = testing::LabelledCaptureForExport;

TEST_F(ExportCommand, ManoLayersOfEveryConventionReproduceTheLabels) {
  std::string npz_specs;
  for (const std::string convention : {"smplx", "manopth", "manotorch"}) {
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
  RecordProperty("cases", report["cases"].dump());  // the measured numbers
  EXPECT_EQ(report["labels"], kExportFrames);       // every label has parameters (fitted)
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
  // 2 layers x 2 flat_hand_mean settings from the labels, manotorch's 4 (both
  // flat_hand_mean, center_idx=9, quaternions), and the 6 npz files' parameters (3
  // conventions x 2 flat_hand_mean), plus their stored arrays.
  EXPECT_EQ(right, 4 + 4 + 6 + 6);
  EXPECT_EQ(wrong, 3);
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
  EXPECT_EQ(csv["rows"], kExportFrames);
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
  EXPECT_EQ(coco["images"], kExportFrames * 8);            // the dexycb rig's 8 views
  EXPECT_GE(coco["hands"].get<int>(), kExportFrames * 6);  // the hand is in most views
  EXPECT_LT(coco["keypoints_2d"].get<double>(), 1e-6);     // pixels
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
  RecordProperty("report", report.dump());  // the measured numbers
  EXPECT_EQ(report["keyframes"], kExportFrames);
  EXPECT_EQ(report["morph_targets"], kExportFrames);
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
