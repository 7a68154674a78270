// The labeling job's network stage against the network it wraps: its 3D answers are
// the network's, carried from the master camera's frame to the rig's world frame; its
// 2D answers are the network's crop pixels seen through the real cameras; and moving
// the whole rig moves the 3D answers with it and leaves the 2D ones alone.

#include "pipeline/network_stage.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "capture/native_frame_source.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "hand/hand_model_io.h"
#include "image/image_file.h"
#include "network/poem/poem_config.h"
#include "tests/apps/label_test_capture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

class NetworkStageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string dir = testing::ScratchDir();
    testing::WriteTestCapture(dir + "/capture", 1, 12);
    PoemConfig c = PoemConfigByName("tiny", 8);
    c.mask_head = true;
    weights_ = dir + "/tiny.pt";
    WriteRandomPoemCheckpoint(c, 6, weights_);
    const NativeFrameSource source(dir + "/capture");
    frame_ = source.Load(source.FrameIds().at(0));
  }
  // A job with these weights, one frame per batch, one thread.
  JobConfig Job() const {
    JobConfig job;
    job.network_weights = weights_;
    job.batch_size = 1;
    job.threads = 1;
    return job;
  }
  std::string weights_;
  FrameInput frame_;
};

TEST_F(NetworkStageTest, AnswersAreTheNetworksInTheRigsFrames) {
  const NetworkStage stage = LoadNetworkStage(Job());
  const MeshPrediction p = stage.predict({&frame_}).at(0);

  // The wrapped network on the same crops.
  HandMeshPredictorOptions options;
  options.weights = weights_;
  options.num_threads = 1;
  const auto network = CreateHandMeshPredictor(options);
  HandCropOptions crop_options;
  crop_options.crop_size = network->crop_size();
  HandMeshInput input;
  std::vector<ViewCrop> crops;
  const Rig& rig = frame_.rig;
  for (size_t v = 0; v < rig.size(); ++v) {
    const ImageU8 image = ReadImageFile(frame_.image_paths[v]);
    HandEvidence evidence;
    ASSERT_TRUE(frame_.keypoints_2d.at(v).has_value());
    evidence.keypoints = frame_.keypoints_2d[v];
    crops.push_back(CropForView({image.width, image.height, image.data.data()},
                                rig[v].camera, evidence, crop_options));
    HandMeshViewInput view;
    view.pixels = crops.back().pixels;
    view.intrinsics = crops.back().intrinsics;
    view.cam_from_master = rig[v].cam_from_world * rig[0].cam_from_world.Inverse();
    view.weight = crops.back().hand_visible ? 1.0 : 0.0;
    input.views.push_back(std::move(view));
  }
  const HandMeshPrediction raw = network->Predict({input}).at(0);

  for (int k = 0; k < kNumHandKeypoints; ++k) {
    // World -> camera 0 (the master frame) gives the network's joints back.
    const Eigen::Vector3d in_master =
        rig[0].cam_from_world * Eigen::Vector3d(p.keypoints.row(k).transpose());
    EXPECT_LT((in_master - raw.joints.row(k).transpose()).norm(), 1e-9) << k;
  }
  ASSERT_EQ(p.keypoints_2d.size(), rig.size());
  // Full-image masks (a warp per view) only for jobs that fit to them.
  EXPECT_TRUE(p.masks.empty());
  JobConfig fits_masks = Job();
  fits_masks.masks = MaskSource::kNetwork;
  EXPECT_EQ(LoadNetworkStage(fits_masks).predict({&frame_}).at(0).masks.size(),
            rig.size());
  for (size_t v = 0; v < rig.size(); ++v) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      // Image pixel -> ray (undistorted) -> crop pixel gives the network's 2D back.
      const Eigen::Vector3d ray =
          rig[v].camera.Unproject(p.keypoints_2d[v].uv_px.row(k).transpose());
      const Eigen::Vector3d crop = crops[v].intrinsics * ray;
      const Keypoints2d& raw_2d = raw.joints_2d[v];
      EXPECT_NEAR(crop.x() / crop.z(), raw_2d.uv_px(k, 0), 1e-6) << v << "," << k;
      EXPECT_NEAR(crop.y() / crop.z(), raw_2d.uv_px(k, 1), 1e-6) << v << "," << k;
      EXPECT_DOUBLE_EQ(p.keypoints_2d[v].confidence(k), raw_2d.confidence(k));
    }
  }
}

TEST_F(NetworkStageTest, MovingTheRigMovesTheAnswerWithIt) {
  const NetworkStage stage = LoadNetworkStage(Job());
  const MeshPrediction a = stage.predict({&frame_}).at(0);
  // new_world = T * world: every camera sees the same, the world frame moved.
  const Rigid3 T(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(0.3, -1.2, 2.0));
  FrameInput moved = frame_;
  for (size_t v = 0; v < moved.rig.size(); ++v) {
    moved.rig[v].cam_from_world = moved.rig[v].cam_from_world * T.Inverse();
  }
  const MeshPrediction b = stage.predict({&moved}).at(0);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const Eigen::Vector3d expected = T * Eigen::Vector3d(a.keypoints.row(k).transpose());
    EXPECT_LT((expected - b.keypoints.row(k).transpose()).norm(), 1e-6) << k;
  }
  for (int i = 0; i < a.vertices.rows(); i += 50) {
    const Eigen::Vector3d expected = T * Eigen::Vector3d(a.vertices.row(i).transpose());
    EXPECT_LT((expected - b.vertices.row(i).transpose()).norm(), 1e-6) << i;
  }
  for (size_t v = 0; v < a.keypoints_2d.size(); ++v) {
    EXPECT_LT((a.keypoints_2d[v].uv_px - b.keypoints_2d[v].uv_px).cwiseAbs().maxCoeff(),
              1e-4)
        << v;
  }
}

// Counts the frames it is asked to predict and passes them to a real network.
class CountingPredictor : public HandMeshPredictor {
 public:
  explicit CountingPredictor(std::unique_ptr<HandMeshPredictor> inner)
      : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  int num_views() const override { return inner_->num_views(); }
  int crop_size() const override { return inner_->crop_size(); }
  bool predicts_masks() const override { return inner_->predicts_masks(); }
  std::vector<HandMeshPrediction> Predict(
      const std::vector<HandMeshInput>& frames) override {
    asked += static_cast<int>(frames.size());
    return inner_->Predict(frames);
  }
  int asked = 0;

 private:
  std::unique_ptr<HandMeshPredictor> inner_;
};

void ExpectSamePrediction(const MeshPrediction& a, const MeshPrediction& b) {
  EXPECT_EQ(a.keypoints, b.keypoints);
  EXPECT_EQ(a.vertices, b.vertices);
  ASSERT_EQ(a.keypoints_2d.size(), b.keypoints_2d.size());
  for (size_t v = 0; v < a.keypoints_2d.size(); ++v) {
    EXPECT_EQ(a.keypoints_2d[v].uv_px, b.keypoints_2d[v].uv_px);
  }
  ASSERT_EQ(a.masks.size(), b.masks.size());
  for (size_t v = 0; v < a.masks.size(); ++v) EXPECT_EQ(a.masks[v], b.masks[v]);
}

// A memo answers an input it has seen (the same crops, poses and weights) without the
// network, with the network's own answer; other crops or other weights go to the
// network.
TEST_F(NetworkStageTest, MemoAnswersSeenInputsAndOnlyThose) {
  HandMeshPredictorOptions options;
  options.weights = weights_;
  options.num_threads = 1;
  CountingPredictor network(CreateHandMeshPredictor(options));
  PredictionMemo memo;
  const MeshPrediction plain = PredictFramesInRig(network, {&frame_}).at(0);
  ASSERT_EQ(network.asked, 1);

  const MeshPrediction first = PredictFramesInRig(network, {&frame_}, &memo, "w1").at(0);
  EXPECT_EQ(network.asked, 2);
  const MeshPrediction again = PredictFramesInRig(network, {&frame_}, &memo, "w1").at(0);
  EXPECT_EQ(network.asked, 2);  // from the memo
  EXPECT_EQ(memo.hits(), 1);
  EXPECT_GT(memo.saved_seconds(), 0.0);  // the first prediction's cost
  ExpectSamePrediction(again, plain);
  ExpectSamePrediction(first, plain);

  // Other 2D keypoints move the crops: a new input. Other weights: a new key.
  FrameInput shifted = frame_;
  shifted.keypoints_2d.at(3)->uv_px.array() += 9.0;
  PredictFramesInRig(network, {&shifted, &frame_}, &memo, "w1");
  EXPECT_EQ(network.asked, 3);  // only the shifted frame
  PredictFramesInRig(network, {&frame_}, &memo, "w2");
  EXPECT_EQ(network.asked, 4);
}

// network.keypoints: the stage's 3D keypoints become the chosen reading of its own
// answer; with a hand model of another topology the joints are read.
TEST_F(NetworkStageTest, KeypointsAreReadAsTheJobSays) {
  const HandModel hand =
      LoadHandModel(std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz");
  JobConfig job = Job();
  const MeshPrediction raw = LoadNetworkStage(job).predict({&frame_}).at(0);
  for (AnswerKeypoints how :
       {AnswerKeypoints::kJoints, AnswerKeypoints::kMesh, AnswerKeypoints::kMean}) {
    job.network_keypoints = how;
    NetworkStage stage = LoadNetworkStage(job);
    ReadAnswerKeypointsAs(job, hand, &stage);
    EXPECT_EQ(stage.keypoints, ToString(how));
    const MeshPrediction p = stage.predict({&frame_}).at(0);
    EXPECT_EQ(p.vertices, raw.vertices);
    EXPECT_TRUE(p.keypoints.isApprox(
        ReadAnswerKeypoints(hand, raw.keypoints, raw.vertices, how), 1e-12))
        << ToString(how);
  }
  EXPECT_FALSE(
      ReadAnswerKeypoints(hand, raw.keypoints, raw.vertices, AnswerKeypoints::kMean)
          .isApprox(raw.keypoints, 1e-6));  // the readings differ here

  // The capsule hand cannot read a 778-vertex mesh: the joints are read, and said so.
  job.network_keypoints = AnswerKeypoints::kMean;
  NetworkStage capsule = LoadNetworkStage(job);
  ReadAnswerKeypointsAs(job, MakeCapsuleHand(HandSide::kRight), &capsule);
  EXPECT_EQ(capsule.predict({&frame_}).at(0).keypoints, raw.keypoints);
  EXPECT_NE(capsule.keypoints.find("joints (mean reads the mesh"), std::string::npos)
      << capsule.keypoints;
}

}  // namespace
}  // namespace handlabel
