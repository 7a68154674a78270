#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "exports/dexycb_layout.h"
#include "exports/ho3d_layout.h"
#include "hand/capsule_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

LabelRecord PosedLabel(const HandModel& model) {
  LabelRecord label;
  label.frame = "000000";
  HandParams params;
  params.global_orient << 0.4, -1.1, 2.0;
  params.hand_pose = Eigen::VectorXd::LinSpaced(kNumPoseParams, -0.3, 0.6);
  params.betas = Eigen::VectorXd::LinSpaced(model.num_betas(), -1.0, 1.5);
  params.transl << 0.12, -0.05, 0.7;
  label.params = params;
  label.mesh = PoseHand(model, params);
  return label;
}

// The model posed with the moved parameters is the label's hand moved: the rotation
// turns about the shaped rest wrist, which the label gives as keypoints_3d[0] - transl.
TEST(DatasetLayouts, ParamsInFramePoseTheMovedHand) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const LabelRecord label = PosedLabel(model);
  const Eigen::Matrix3d gl = Eigen::Vector3d(1, -1, -1).asDiagonal();  // HO3D's flip
  for (const Eigen::Matrix3d& rotation :
       {Eigen::Matrix3d(Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, 2, -1).normalized())),
        Eigen::Matrix3d(gl * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())),
        Eigen::Matrix3d(Eigen::AngleAxisd(3.1, Eigen::Vector3d::UnitZ()))}) {
    const Eigen::Vector3d translation(-0.2, 0.3, 1.1);
    const HandMesh moved = PoseHand(model, ParamsInFrame(label, rotation, translation));
    const Points3d expected =
        (label.mesh.vertices * rotation.transpose()).rowwise() + translation.transpose();
    EXPECT_LT((moved.vertices - expected).cwiseAbs().maxCoeff(), 1e-12);
  }
  // Turning about the origin instead (transl rotated as if it were the wrist) is not
  // the same hand: the rest wrist matters.
  HandParams naive = ParamsInFrame(label, Eigen::Matrix3d::Identity(), {0, 0, 0});
  naive.transl = Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitX()) * label.params->transl;
  EXPECT_GT((PoseHand(model, naive).vertices - label.mesh.vertices).norm(), 1e-3);
}

SeriesCapture OneCamera(int width, int height, bool distortion) {
  SeriesCapture capture;
  const CameraModelId id = distortion ? CameraModelId::kOpenCV : CameraModelId::kPinhole;
  std::vector<double> params = {500, 500, width / 2.0, height / 2.0};
  if (distortion) params.insert(params.end(), {0.1, 0, 0, 0});
  capture.rig.Add({"cam0", Camera(id, width, height, params), Rigid3()});
  capture.images = {{"/nonexistent.png"}};
  return capture;
}

TEST(DatasetLayouts, WhatALayoutCannotHoldIsNamed) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const std::string dir = testing::ScratchDir();
  LabelSeries series;
  series.labels_dir = dir + "/labels";
  series.labels = {PosedLabel(model)};
  const DatasetLayoutOptions options{dir + "/out", ImagePlacement::kLink};
  std::string message = testing::InputErrorOf(
      [&] { WriteHo3dLayout(series, OneCamera(160, 120, false), options); });
  EXPECT_NE(message.find("640 x 480"), std::string::npos) << message;
  EXPECT_NE(message.find("got 160 x 120"), std::string::npos) << message;
  message = testing::InputErrorOf(
      [&] { WriteHo3dLayout(series, OneCamera(640, 480, true), options); });
  EXPECT_NE(message.find("camera cam0"), std::string::npos) << message;
  EXPECT_NE(message.find("distortion"), std::string::npos) << message;
  message = testing::InputErrorOf(
      [&] { WriteDexYcbLayout(series, model, OneCamera(640, 480, true), options); });
  EXPECT_NE(message.find("distortion"), std::string::npos) << message;
  series.labels[0].params.reset();  // a network-path label
  message = testing::InputErrorOf(
      [&] { WriteDexYcbLayout(series, model, OneCamera(640, 480, false), options); });
  EXPECT_NE(message.find("000000.json"), std::string::npos) << message;
  EXPECT_NE(message.find("field 'mano'"), std::string::npos) << message;
}

}  // namespace
}  // namespace handlabel
