// `handlabel export --format dexycb|ho3d`: the labels of a real label job written in
// the datasets' layouts, then read back two ways:
//   - tests/apps/dataset_readers.py reads them as dex-ycb-toolkit and the HO3D
//     repository do (their file layouts, conventions and MANO layers, re-implemented in
//     NumPy): every number must be the labels' (to float32 storage);
//   - our own in-place readers (input.format dexycb / ho3d, the frame sources a label
//     job uses) must give the labels' keypoints as ground truth to 1e-6 m, DexYCB's
//     joint_2d as the labels projected, and the capture's rig; and a label job run in
//     place on the DexYCB export fits back onto the labels.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "capture/capture_reader.h"
#include "capture/dexycb_frame_source.h"
#include "capture/ho3d_frame_source.h"
#include "exports/label_series.h"
#include "tests/apps/export_fixture.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::kExportFrames;
using testing::RunHandlabelCommand;

using ExportDatasets = testing::LabelledCaptureForExport;

// Largest distance between the reader's ground truth and the labels' keypoints.
double GroundTruthError(const FrameSource& source, const LabelSeries& series,
                        const std::vector<std::string>& ids) {
  double worst = 0;
  EXPECT_EQ(ids.size(), series.labels.size());
  for (size_t f = 0; f < ids.size() && f < series.labels.size(); ++f) {
    const FrameInput frame = source.Load(ids[f]);
    EXPECT_TRUE(frame.ground_truth.has_value()) << ids[f];
    if (!frame.ground_truth) continue;
    worst =
        std::max(worst, (frame.ground_truth->keypoints - series.labels[f].mesh.keypoints)
                            .cwiseAbs()
                            .maxCoeff());
  }
  return worst;
}

// Largest camera centre distance between two rigs with the same camera order.
double RigError(const Rig& a, const Rig& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0;
  for (size_t c = 0; c < std::min(a.size(), b.size()); ++c) {
    worst = std::max(worst, (a[c].CenterInWorld() - b[c].CenterInWorld()).norm());
    EXPECT_NEAR(a[c].camera.fx(), b[c].camera.fx(), 1e-9);
    EXPECT_NEAR(a[c].camera.cy(), b[c].camera.cy(), 1e-9);
  }
  return worst;
}

TEST_F(ExportDatasets, DexYcbLayoutReadsBackAsTheToolkitAndOurReaderRead) {
  const std::string out = *dir_ + "/dexycb";
  const auto r = RunHandlabelCommand(
      {"export", "--labels", OutDir(), "--format", "dexycb", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report =
      RunPython("dataset_readers.py", "--model " + ModelPath() + " --labels " + OutDir() +
                                          "/labels --dexycb " + out);
  ASSERT_TRUE(report.contains("dexycb")) << report.dump();
  const nlohmann::json& dex = report["dexycb"];
  RecordProperty("dexycb_report", dex.dump());  // the measured numbers, in the XML/JSON
  EXPECT_EQ(dex["frames"], kExportFrames);
  EXPECT_EQ(dex["views"], kExportFrames * 8);
  EXPECT_TRUE(dex["images_exist"].get<bool>());
  EXPECT_LT(dex["joint_3d"].get<double>(), 1e-6);  // metres, float32 storage
  EXPECT_LT(dex["joint_2d_px"].get<double>(), 1e-3);
  // pose_m through the toolkit's manopth layer (PCA, hands_mean added, mm / 1000)
  // is the label's hand seen from that camera.
  EXPECT_LT(dex["pose_m_joints"].get<double>(), 1e-6);
  EXPECT_LT(dex["pose_m_vertices"].get<double>(), 1e-6);
  EXPECT_LT(dex["betas_as_labels"].get<double>(), 1e-6);
  EXPECT_LT(dex["mano_yml_betas"].get<double>(), 1e-12);  // the first label's, as text
  EXPECT_GT(dex["WRONG pose_m as full axis-angle"].get<double>(), 1e-3);
  RecordProperty("pose_m_vertices_nm",
                 static_cast<int>(1e9 * dex["pose_m_vertices"].get<double>()));

  // Our in-place reader: the labels come back as ground truth, the rig as captured.
  const LabelSeries series = ReadLabelSeries(OutDir());
  const DexYcbFrameSource source(out + "/handlabel/out");
  const double truth_error = GroundTruthError(source, series, source.FrameIds());
  RecordProperty("reader_truth_nm", static_cast<int>(1e9 * truth_error));
  EXPECT_LT(truth_error, 1e-6);
  const CaptureReader capture(CaptureDir());
  EXPECT_LT(RigError(source.sequences()[0].rig, capture.rig()), 1e-9);
  const FrameInput first = source.Load("000000");
  ASSERT_EQ(first.keypoints_2d.size(), 8u);
  for (size_t v = 0; v < first.keypoints_2d.size(); ++v) {
    ASSERT_TRUE(first.keypoints_2d[v].has_value());
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      Eigen::Vector2d uv;
      ASSERT_TRUE(first.rig[v].ProjectWorld(
          series.labels[0].mesh.keypoints.row(k).transpose(), &uv));
      EXPECT_LT((first.keypoints_2d[v]->uv_px.row(k).transpose() - uv).norm(), 1e-3);
    }
  }

  // A label job in place on the export: fits to its joint_2d land on the labels.
  const std::string job = *dir_ + "/in_place.yaml";
  std::ofstream(job) << "name: in-place\nseed: 1\nhand_model: " << ModelPath()
                     << "\ninput: {format: dexycb, path: " << out << "/handlabel/out}\n"
                     << "network: {threads: 2}\nrefine: {mode: always}\n"
                     << "evidence: {keypoints_2d: files, masks: none}\n"
                     << "output: {dir: " << *dir_ << "/in_place, overlays: false}\n";
  const auto label = RunHandlabelCommand({"label", "--job", job, "--quiet"});
  ASSERT_EQ(label.status, 0) << label.err;
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadFileBytes(*dir_ + "/in_place/summary.json"));
  const double mpjpe_mm = summary.at("metrics").at("labels").at("mpjpe_mm").get<double>();
  RecordProperty("in_place_mpjpe_um", static_cast<int>(1000 * mpjpe_mm));
  EXPECT_LT(mpjpe_mm, 1.0);
}

TEST_F(ExportDatasets, Ho3dLayoutReadsBackAsItsScriptsAndOurReaderRead) {
  const std::string out = *dir_ + "/ho3d";
  const auto r = RunHandlabelCommand({"export", "--labels", OutDir(), "--format", "ho3d",
                                      "--out", out, "--images", "copy"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report =
      RunPython("dataset_readers.py", "--model " + ModelPath() + " --labels " + OutDir() +
                                          "/labels --ho3d " + out);
  ASSERT_TRUE(report.contains("ho3d")) << report.dump();
  const nlohmann::json& ho3d = report["ho3d"];
  RecordProperty("ho3d_report", ho3d.dump());
  EXPECT_EQ(ho3d["cameras"], 8);
  EXPECT_EQ(ho3d["metas"], kExportFrames * 8);
  EXPECT_TRUE(ho3d["images_exist"].get<bool>());
  EXPECT_LT(ho3d["joints_3d"].get<double>(), 1e-6);  // OpenGL axes, MANO order + tips
  // handPose / handTrans / handBeta through HO3D's flat_hand_mean=True MANO: the
  // label's hand in that camera's OpenGL frame.
  EXPECT_LT(ho3d["fk_joints"].get<double>(), 1e-6);
  EXPECT_LT(ho3d["fk_vertices"].get<double>(), 1e-6);
  EXPECT_LT(ho3d["fk_label_tips"].get<double>(), 1e-6);
  EXPECT_LT(ho3d["cam_mat"].get<double>(), 1e-4);  // float32 of ~500 px
  EXPECT_GT(ho3d["WRONG handJoints3D without GL flip"].get<double>(), 1e-3);
  const std::string image = out + "/train/HANDLABEL0/rgb/0000.png";  // copied
  EXPECT_TRUE(fs::is_regular_file(image));
  EXPECT_FALSE(fs::is_symlink(image));

  const LabelSeries series = ReadLabelSeries(OutDir());
  const Ho3dFrameSource source(out + "/train/HANDLABEL");
  const double truth_error = GroundTruthError(source, series, source.FrameIds());
  RecordProperty("reader_truth_nm", static_cast<int>(1e9 * truth_error));
  EXPECT_LT(truth_error, 1e-6);
  const CaptureReader capture(CaptureDir());
  EXPECT_LT(RigError(source.sequences()[0].rig, capture.rig()), 1e-9);
}

}  // namespace
}  // namespace handlabel
