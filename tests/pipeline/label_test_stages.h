#pragma once
// In-memory stages for testing the labeling runner without the network, the fitter or
// files: a synthetic capture of the stick hand (tests/hand/stick_hand.h) seen by four
// cameras with exact ground truth, a predictor that returns the ground truth with
// chosen defects, and a fitter that triangulates the 2D evidence. They exercise the
// orchestration (policy, resume, shards, failure isolation); label quality with the
// real network and fitter is tested where those live and in the end-to-end tests.

#include <atomic>
#include <chrono>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>

#include "geometry/triangulation.h"
#include "pipeline/label_job.h"
#include "pipeline/label_policy.h"
#include "tests/hand/stick_hand.h"

namespace handlabel::testing {

// A job over the test capture with a network (the test predictor) and `mode`.
inline JobConfig MakeTestJob(const std::string& out, RefineMode mode) {
  JobConfig job;
  job.source_file = "test.yaml";
  job.name = "test";
  job.seed = 5;
  job.input_path = "memory";
  job.output_dir = out;
  job.refine_mode = mode;
  job.threads = 2;
  job.batch_size = 3;
  job.network_weights = "weights.pt";
  job.meshes = {"ply"};
  return job;
}

inline Rig MakeFourCameraRig() {
  Rig rig;
  for (int i = 0; i < 4; ++i) {
    // Cameras on a circle of radius 0.6 m around the origin, looking at it.
    const double angle = 2.0 * M_PI * i / 4.0 + 0.3;
    const Eigen::Vector3d center(0.6 * std::cos(angle), 0.15 * (i % 2 ? 1 : -1),
                                 0.6 * std::sin(angle));
    const Eigen::Vector3d z = -center.normalized();
    const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d world_from_cam;
    world_from_cam << x, y, z;
    const Eigen::Quaterniond cam_from_world_rotation(world_from_cam.transpose());
    RigCamera camera;
    camera.name = "cam" + std::to_string(i);
    camera.camera = Camera::Pinhole(600, 600, 320, 240, 640, 480);
    camera.cam_from_world =
        Rigid3(cam_from_world_rotation, -(cam_from_world_rotation * center));
    rig.Add(camera);
  }
  return rig;
}

inline Keypoints2d ProjectKeypoints(const RigCamera& camera, const Points3d& keypoints) {
  Keypoints2d view;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    Eigen::Vector2d uv;
    camera.ProjectWorld(keypoints.row(k).transpose(), &uv);
    view.uv_px.row(k) = uv.transpose();
    view.confidence(k) = 1.0;
  }
  return view;
}

class TestCapture : public FrameSource {
 public:
  explicit TestCapture(int num_frames, uint64_t seed = 1)
      : model_(MakeStickHand(HandSide::kRight)), rig_(MakeFourCameraRig()) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> pose(0.0, 0.15);
    std::uniform_real_distribution<double> offset(-0.05, 0.05);
    for (int f = 0; f < num_frames; ++f) {
      char id[16];
      std::snprintf(id, sizeof(id), "%06d", f);
      HandParams params;
      for (int i = 0; i < 3; ++i) params.global_orient[i] = pose(rng);
      for (int i = 0; i < kNumPoseParams; ++i) params.hand_pose[i] = pose(rng);
      params.betas = Eigen::VectorXd::Zero(10);
      params.transl = Eigen::Vector3d(offset(rng) + 0.08, offset(rng), offset(rng));
      ids_.push_back(id);
      params_.push_back(params);
    }
  }

  std::vector<std::string> FrameIds() const override {
    std::vector<std::string> ids = ids_;
    if (!duplicate.empty()) ids.push_back(duplicate);  // a capture listing it twice
    return ids;
  }

  FrameInput Load(const std::string& id) const override {
    ++loads;
    if (unreadable.count(id)) throw std::runtime_error("cannot read image of " + id);
    const size_t f = std::find(ids_.begin(), ids_.end(), id) - ids_.begin();
    if (f == ids_.size()) throw std::runtime_error("no frame " + id);
    FrameInput frame;
    frame.id = id;
    frame.rig = rig_;
    const HandMesh mesh = PoseHand(model_, params_[f]);
    FrameGroundTruth truth;
    truth.keypoints = mesh.keypoints;
    truth.vertices = mesh.vertices;
    truth.params = params_[f];
    frame.ground_truth = truth;
    for (const RigCamera& camera : rig_.cameras()) {
      frame.image_paths.push_back("/nonexistent/" + camera.name + "/" + id + ".png");
      if (!without_2d)
        frame.keypoints_2d.push_back(ProjectKeypoints(camera, mesh.keypoints));
    }
    return frame;
  }

  std::string Describe() const override {
    return "test capture, " + std::to_string(ids_.size()) + " frames";
  }

  const HandModel& model() const { return model_; }
  std::set<std::string> unreadable;
  std::string duplicate;    // a frame id FrameIds() lists a second time (bad captures)
  bool without_2d = false;  // frames without 2D keypoints (a detector finds them later)
  mutable std::atomic<int> loads{0};

 private:
  HandModel model_;
  Rig rig_;
  std::vector<std::string> ids_;
  std::vector<HandParams> params_;
};

// The ground truth, with a 3 cm error on frames in `shifted` (fails quality checks) and
// an exception for frames in `throws`.
class TestPredictor : public NetworkStage {
 public:
  TestPredictor() {
    model_name = "test-predictor";
    weights_sha256 = std::string(64, 'a');
    predict = [this](const std::vector<const FrameInput*>& frames) {
      return Predict(frames);
    };
  }
  std::vector<MeshPrediction> Predict(const std::vector<const FrameInput*>& frames) {
    ++batches;
    const InsideCount inside(this);
    // With lanes, wait for a second batch to come in (or `hold` to pass), so that a
    // runner which lets batches overlap shows it whatever the machine's load.
    const auto until = std::chrono::steady_clock::now() + hold;
    while (lanes > 1 && inside_.load() < 2 && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    // ... and stay a little, so that a runner letting in more than `lanes` is caught.
    if (hold.count() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::vector<MeshPrediction> out;
    for (const FrameInput* frame : frames) {
      if (throws.count(frame->id))
        throw std::runtime_error("network exploded on " + frame->id);
      MeshPrediction p;
      p.keypoints = frame->ground_truth->keypoints;
      p.vertices = frame->ground_truth->vertices;
      if (shifted.count(frame->id)) {
        p.keypoints.col(0).array() += 0.03;
        p.vertices.col(0).array() += 0.03;
      }
      for (const RigCamera& camera : frame->rig.cameras()) {
        p.keypoints_2d.push_back(
            ProjectKeypoints(camera, frame->ground_truth->keypoints));
      }
      out.push_back(p);
      ++predicted;
    }
    return out;
  }
  std::set<std::string> shifted;
  std::set<std::string> throws;
  // With lanes > 1: the longest a batch waits inside Predict for another to join it.
  std::chrono::milliseconds hold{0};
  std::atomic<int> batches{0};
  std::atomic<int> predicted{0};
  std::atomic<int> most_inside{0};  // the most batches inside Predict at once

 private:
  // Counts the batches inside Predict while it lives.
  class InsideCount {
   public:
    explicit InsideCount(TestPredictor* p) : p_(p) {
      const int now = ++p_->inside_;
      int most = p_->most_inside.load();
      while (now > most && !p_->most_inside.compare_exchange_weak(most, now)) {
      }
    }
    ~InsideCount() { --p_->inside_; }

   private:
    TestPredictor* p_;
  };
  std::atomic<int> inside_{0};
};

// Triangulates each keypoint from the evidence (a stand-in for the Ceres fitter with
// the same contract); throws for frames in `throws`.
class TestFitter : public LabelFitter {
 public:
  LabelFit Fit(const LabelFitRequest& request) const override {
    ++fits;
    if (throws.count(request.frame->id)) throw std::runtime_error("solver diverged");
    LabelFit result;
    result.mesh.keypoints.resize(kNumHandKeypoints, 3);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      std::vector<ViewObservation> observations;
      for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
        const auto& view = request.keypoints_2d[v];
        if (view) observations.push_back({int(v), view->uv_px.row(k).transpose(), 1.0});
      }
      const auto point = TriangulateWeighted(request.frame->rig, observations);
      if (!point) throw std::runtime_error("cannot triangulate");
      result.mesh.keypoints.row(k) = point->transpose();
    }
    result.mesh.joints = NativeJointsFromKeypoints(result.mesh.keypoints);
    result.mesh.vertices =
        request.frame->ground_truth->vertices;  // stick hand: 21 vertices
    result.params.betas = Eigen::VectorXd::Zero(10);
    result.report = {{"refined_from_network", request.init != nullptr},
                     {"seed", request.seed}};
    return result;
  }
  std::string Describe() const override { return "test fitter"; }
  std::set<std::string> throws;
  mutable std::atomic<int> fits{0};
};

// A test job's stages: its capture, network (nullptr: none) and fitter, with the
// capture's hand model named and its faces for the mesh files.
inline LabelStageSet TestStageSet(const TestCapture& capture, const NetworkStage* network,
                                  const LabelFitter* fitter) {
  LabelStageSet set;
  set.source = &capture;
  set.predictor = network;
  set.fitter = fitter;
  set.hand_model_name = capture.model().name;
  set.faces = capture.model().faces;
  return set;
}

}  // namespace handlabel::testing
