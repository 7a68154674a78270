#include "pipeline/quality_checks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/errors.h"
#include "tests/pipeline/label_test_stages.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::MakeFourCameraRig;
using testing::ProjectKeypoints;

// The stick hand in a random pose near the origin, with exact 2D keypoints in all views.
MeshPrediction ExactPrediction(const Rig& rig) {
  const HandModel model = testing::MakeStickHand(HandSide::kRight);
  HandParams params;
  params.global_orient = testing::RandomVector3(-0.3, 0.3);
  for (int i = 0; i < kNumPoseParams; ++i) params.hand_pose[i] = testing::Gaussian(0.1);
  params.transl = Eigen::Vector3d(0.08, 0, 0) + testing::RandomVector3(-0.03, 0.03);
  const HandMesh mesh = PoseHand(model, params);
  MeshPrediction p;
  p.keypoints = mesh.keypoints;
  p.vertices = mesh.vertices;
  for (const RigCamera& camera : rig.cameras()) {
    p.keypoints_2d.push_back(ProjectKeypoints(camera, mesh.keypoints));
  }
  return p;
}

const QualityFlag& Flag(const QualityReport& report, const std::string& name) {
  for (const QualityFlag& f : report.flags) {
    if (f.name == name) return f;
  }
  throw std::runtime_error("no flag " + name);
}

TEST(QualityChecks, AnExactPredictionPassesEveryCheck) {
  const Rig rig = MakeFourCameraRig();
  const QualityReport report = CheckPrediction(rig, ExactPrediction(rig), {});
  ASSERT_EQ(report.flags.size(), 5u);
  EXPECT_TRUE(report.Passed()) << report.FailedNames();
  EXPECT_NEAR(Flag(report, "reprojection").value, 0.0, 1e-6);
  EXPECT_NEAR(Flag(report, "view_agreement").value, 0.0, 1e-6);
  EXPECT_EQ(Flag(report, "enough_views").value, 4);
  EXPECT_GT(Flag(report, "range").value, 0.1);  // the stick hand spans ~19 cm
  EXPECT_LT(Flag(report, "range").value, 0.25);
}

TEST(QualityChecks, A3dOffsetFailsReprojectionAndViewAgreementWithTheRightSize) {
  const Rig rig = MakeFourCameraRig();
  MeshPrediction p = ExactPrediction(rig);
  p.keypoints.rowwise() += Eigen::RowVector3d(0.02, 0, 0);  // 2D stays at the truth
  const QualityReport report = CheckPrediction(rig, p, {});
  EXPECT_EQ(report.FailedNames(), "reprojection,view_agreement");
  EXPECT_NEAR(Flag(report, "view_agreement").value, 20.0, 1e-6);  // exactly the offset
  // 2 cm at ~0.6 m with f = 600 px moves a point by up to ~20 px.
  EXPECT_GT(Flag(report, "reprojection").value, 12.0);
}

// A self-consistent answer away from the hand passes the checks against its own 2D;
// only the detector's 2D exposes it. The value is the median view's RMS, so one view
// whose detector found something else does not fail a good answer.
TEST(QualityChecks, DetectorAgreementJudgesTheAnswerAgainstFile2d) {
  const Rig rig = MakeFourCameraRig();
  const MeshPrediction truth = ExactPrediction(rig);
  std::vector<std::optional<Keypoints2d>> files(truth.keypoints_2d.begin(),
                                                truth.keypoints_2d.end());
  files[2]->uv_px.col(0).array() += 100.0;  // one view's detector is far off
  files[3].reset();                         // and one view has no detection
  const QualityReport exact = CheckPrediction(rig, truth, {}, &files);
  ASSERT_EQ(exact.flags.size(), 6u);
  EXPECT_TRUE(exact.Passed()) << exact.FailedNames();
  // Views 0 and 1 agree exactly, view 2 is 100 px off: the median of {0, 0, 100}.
  EXPECT_NEAR(Flag(exact, "detector_agreement").value, 0.0, 1e-6);

  // The whole answer moved 2 cm with its own 2D projected along: self-consistent.
  MeshPrediction moved = truth;
  moved.keypoints.rowwise() += Eigen::RowVector3d(0.02, 0, 0);
  moved.keypoints_2d.clear();
  for (const RigCamera& camera : rig.cameras()) {
    moved.keypoints_2d.push_back(ProjectKeypoints(camera, moved.keypoints));
  }
  EXPECT_TRUE(CheckPrediction(rig, moved, {}).Passed());
  const QualityReport judged = CheckPrediction(rig, moved, {}, &files);
  EXPECT_EQ(judged.FailedNames(), "detector_agreement");
  // The median of views 0, 1 and 2 (each view's RMS of its 21 keypoints' shift),
  // computed here from the projections.
  std::vector<double> rms;
  for (int v = 0; v < 3; ++v) {
    const Keypoints2d now = ProjectKeypoints(rig[v], moved.keypoints);
    rms.push_back(std::sqrt((now.uv_px - files[v]->uv_px).rowwise().squaredNorm().mean()));
  }
  std::sort(rms.begin(), rms.end());
  EXPECT_NEAR(Flag(judged, "detector_agreement").value, rms[1], 1e-9);

  QualityThresholds loose;
  loose.max_detector_rms_px = rms[1] + 1;
  EXPECT_TRUE(CheckPrediction(rig, moved, loose, &files).Passed());
}

TEST(QualityChecks, DetectorAgreementFailsWithoutAConfidentFileView) {
  const Rig rig = MakeFourCameraRig();
  const MeshPrediction truth = ExactPrediction(rig);
  std::vector<std::optional<Keypoints2d>> files(rig.size());
  files[0] = truth.keypoints_2d[0];
  files[0]->confidence.setConstant(0.1);  // below min_confidence
  const QualityReport report = CheckPrediction(rig, truth, {}, &files);
  EXPECT_EQ(report.FailedNames(), "detector_agreement");
  // No file 2D at all (an empty list): the check is not made.
  const std::vector<std::optional<Keypoints2d>> none;
  EXPECT_EQ(CheckPrediction(rig, truth, {}, &none).flags.size(), 5u);
}

TEST(QualityChecks, ThresholdsComeFromTheJob) {
  const Rig rig = MakeFourCameraRig();
  MeshPrediction p = ExactPrediction(rig);
  p.keypoints.rowwise() += Eigen::RowVector3d(0.005, 0, 0);
  QualityThresholds loose;
  EXPECT_TRUE(CheckPrediction(rig, p, loose).Passed());
  QualityThresholds strict;
  strict.max_view_disagreement_mm = 4.0;
  strict.max_reprojection_px = 1.0;
  EXPECT_EQ(CheckPrediction(rig, p, strict).FailedNames(), "reprojection,view_agreement");
}

TEST(QualityChecks, OneBadViewFailsReprojectionAndNamesThatView) {
  const Rig rig = MakeFourCameraRig();
  MeshPrediction p = ExactPrediction(rig);
  p.keypoints_2d[2].uv_px.col(0).array() += 30.0;
  const QualityReport report = CheckPrediction(rig, p, {});
  EXPECT_FALSE(Flag(report, "reprojection").passed);
  EXPECT_NEAR(Flag(report, "reprojection").value, 30.0, 1e-6);
  EXPECT_THAT(Flag(report, "reprojection").detail, ::testing::HasSubstr("cam2"));
}

TEST(QualityChecks, LowConfidenceViewsDoNotCountAsEvidence) {
  const Rig rig = MakeFourCameraRig();
  MeshPrediction p = ExactPrediction(rig);
  for (int v = 0; v < 3; ++v) p.keypoints_2d[v].confidence.setConstant(0.1);
  p.keypoints_2d[0].uv_px.array() += 50.0;  // ignored: not confident
  const QualityReport report = CheckPrediction(rig, p, {});
  EXPECT_EQ(Flag(report, "enough_views").value, 1);
  EXPECT_FALSE(Flag(report, "enough_views").passed);
  EXPECT_TRUE(Flag(report, "reprojection").passed);
  EXPECT_FALSE(Flag(report, "view_agreement").passed);  // one view cannot triangulate
}

TEST(QualityChecks, NanFailsFiniteAndEverythingElse) {
  const Rig rig = MakeFourCameraRig();
  MeshPrediction p = ExactPrediction(rig);
  p.vertices(3, 1) = std::nan("");
  const QualityReport report = CheckPrediction(rig, p, {});
  EXPECT_EQ(Flag(report, "finite").value, 1);
  EXPECT_EQ(report.FailedNames(),
            "finite,range,enough_views,reprojection,view_agreement");
}

TEST(QualityChecks, ImplausibleSizeOrAHandBehindACameraFailsRange) {
  const Rig rig = MakeFourCameraRig();
  MeshPrediction tiny = ExactPrediction(rig);
  const Eigen::RowVector3d center = tiny.keypoints.colwise().mean();
  tiny.keypoints = ((tiny.keypoints.rowwise() - center) * 0.1).rowwise() + center;
  EXPECT_FALSE(Flag(CheckPrediction(rig, tiny, {}), "range").passed);

  MeshPrediction behind = ExactPrediction(rig);
  behind.keypoints.rowwise() += 1.5 * rig[0].CenterInWorld().transpose();
  EXPECT_FALSE(Flag(CheckPrediction(rig, behind, {}), "range").passed);
}

// Silhouette conflict: per-view keypoint RMS and IoU of a silhouette fit against the
// keypoints-only fit it started from. Views without keypoints (NaN) do not count.
HandFitStageResult StageWith(std::vector<double> rms, std::vector<double> iou) {
  HandFitStageResult r;
  r.view_rms_px = std::move(rms);
  r.view_iou = std::move(iou);
  return r;
}

TEST(SilhouetteCheck, AgreeingFitsPass) {
  const double nan = std::nan("");
  const HandFitStageResult kp = StageWith({2.0, 3.0, nan}, {0.80, 0.70, nan});
  const HandFitStageResult sil = StageWith({2.1, 3.1, nan}, {0.90, 0.85, nan});
  const QualityReport r = CheckSilhouetteFit(sil, kp, {});
  ASSERT_EQ(r.flags.size(), 2u);
  EXPECT_TRUE(r.Passed()) << r.FailedNames();
  EXPECT_NEAR(Flag(r, "keypoint_agreement").value, 0.1, 1e-12);  // (0.1 + 0.1) / 2
  EXPECT_NEAR(Flag(r, "silhouette_iou").value, 0.85, 1e-12);
}

TEST(SilhouetteCheck, ASilhouetteFitThatLeavesTheKeypointsFails) {
  const HandFitStageResult kp = StageWith({2.0, 3.0}, {0.80, 0.70});
  SilhouetteCheckThresholds t;
  t.max_keypoint_rms_rise_px = 0.5;
  // Mean rise (0.4 + 0.8) / 2 = 0.6 px > 0.5.
  const QualityReport r = CheckSilhouetteFit(StageWith({2.4, 3.8}, {0.9, 0.9}), kp, t);
  EXPECT_EQ(r.FailedNames(), "keypoint_agreement");
  EXPECT_NEAR(Flag(r, "keypoint_agreement").value, 0.6, 1e-12);
  // At the threshold it passes.
  EXPECT_TRUE(CheckSilhouetteFit(StageWith({2.4, 3.6}, {0.9, 0.9}), kp, t).Passed());
}

TEST(SilhouetteCheck, AViewWhoseMaskTheFitMissesFailsIou) {
  const HandFitStageResult kp = StageWith({2.0, 3.0}, {0.80, 0.70});
  SilhouetteCheckThresholds t;
  t.min_view_iou = 0.5;
  const QualityReport r = CheckSilhouetteFit(StageWith({2.0, 3.0}, {0.9, 0.3}), kp, t);
  EXPECT_EQ(r.FailedNames(), "silhouette_iou");
  EXPECT_NEAR(Flag(r, "silhouette_iou").value, 0.3, 1e-12);
  t.min_view_iou = -0.1;
  EXPECT_THROW(t.Check("test"), InputError);
}

}  // namespace
}  // namespace handlabel
