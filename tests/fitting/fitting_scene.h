#pragma once
// Synthetic multi-view scenes for fitting tests and benches: a DexYCB-like rig (8
// cameras, 640x480, f ~ 615 px, mild OpenCV distortion, 0.55-0.8 m from the hand), a
// hand in a natural random pose (hand/hand_pose_sampler.h) with random shape, root
// rotation and position, and its exact 2D keypoints in every view. Noise, outliers and
// occluded views are added by the caller.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fitting/keypoint_view.h"
#include "geometry/rig.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_lbs.h"
#include "hand/hand_pose_sampler.h"
#include "image/mask_image.h"
#include "image/mesh_primitives.h"
#include "image/rasterizer.h"

namespace handlabel::testing {

// image_scale < 1 shrinks the images (and the focal lengths) for fast tests.
inline std::vector<RigCamera> DexYcbLikeRig(double image_scale = 1.0) {
  std::vector<RigCamera> cameras;
  for (int i = 0; i < 8; ++i) {
    const double azimuth = 2.0 * M_PI * i / 8.0 + 0.2;
    const double elevation = (i % 2 == 0 ? 0.9 : 0.5);  // radians above the table
    const double distance = 0.55 + 0.035 * i;
    const Eigen::Vector3d eye(distance * std::cos(elevation) * std::cos(azimuth),
                              -distance * std::sin(elevation),
                              distance * std::cos(elevation) * std::sin(azimuth));
    RigCamera cam;
    cam.name = "cam" + std::to_string(i);
    cam.camera = Camera(CameraModelId::kOpenCV, 640, 480,
                        {615.0 + 3 * i, 613.0 + 2 * i, 320.0 + i, 240.0 - i,
                         -0.04 + 0.01 * i, 0.02, 0.0005, -0.0004},
                        "DexYcbLikeRig");
    cam.cam_from_world = LookAt(eye, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -1, 0));
    cameras.push_back(cam);
  }
  return cameras;
}

struct SceneFrame {
  HandParams params;
  HandMesh mesh;
  std::vector<KeypointView> views;  // exact projections, confidence 1
};

inline SceneFrame RandomSceneFrame(const HandModel& model, std::mt19937_64& rng,
                                   double betas_sigma = 0.8, double image_scale = 1.0) {
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  SceneFrame f;
  f.params.hand_pose =
      SampleHandPose(anatomy, DefaultHandLimits(), HandPoseSamplerOptions(), rng)
          .hand_pose;
  std::normal_distribution<double> g(0.0, 1.0);
  f.params.betas = Eigen::VectorXd(10);
  for (int s = 0; s < 10; ++s) f.params.betas[s] = betas_sigma * g(rng);
  Eigen::Vector4d q(g(rng), g(rng), g(rng), g(rng));
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized());
  f.params.global_orient = aa.angle() * aa.axis();
  // Place the hand's centre near the rig's centre.
  const HandMesh at_origin = PoseHand(model, f.params);
  const Eigen::Vector3d centre = at_origin.keypoints.colwise().mean().transpose();
  f.params.transl = -centre + 0.04 * Eigen::Vector3d(g(rng), g(rng), g(rng));
  f.mesh = PoseHand(model, f.params);
  for (const RigCamera& cam : DexYcbLikeRig(image_scale)) {
    KeypointView view;
    view.camera = cam;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      Eigen::Vector2d uv;
      const bool ok = cam.ProjectWorld(f.mesh.keypoints.row(k).transpose(), &uv);
      view.keypoints.uv_px.row(k) = uv.transpose();
      view.keypoints.confidence[k] = ok ? 1.0 : 0.0;
    }
    f.views.push_back(view);
  }
  return f;
}

// sigma_px Gaussian noise on every keypoint, a fraction of keypoints replaced by
// uniform outliers in the image, and the listed views occluded (confidence 0).
inline void CorruptViews(std::vector<KeypointView>* views, double sigma_px,
                         double outlier_fraction, const std::vector<int>& occluded,
                         std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, sigma_px);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (KeypointView& view : *views) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (u(rng) < outlier_fraction) {
        view.keypoints.uv_px(k, 0) = view.camera.camera.width() * u(rng);
        view.keypoints.uv_px(k, 1) = view.camera.camera.height() * u(rng);
      } else {
        view.keypoints.uv_px(k, 0) += g(rng);
        view.keypoints.uv_px(k, 1) += g(rng);
      }
    }
  }
  for (int v : occluded) (*views)[v].keypoints.confidence.setZero();
}

// A ball held against the fingers: radius 2.5 cm, centred 2 cm off the middle of the
// index and middle fingers (PIP and DIP keypoints) on the palm side. Per view: the
// visible hand pixels (replacing the full hand mask), the ball's pixels (the occluder
// mask, 255) and which keypoints the ball hides. A detector sees those worse: they get
// confidence 0.3 and `hidden_sigma_px` of extra Gaussian noise (the rule of
// capture/synth_detections.h in short).
struct HeldBall {
  std::vector<MaskImage> hand_masks;
  std::vector<MaskImage> occluder_masks;
  int hidden_keypoints = 0;  // over all views
};

inline HeldBall HoldBall(const HandModel& model, SceneFrame* frame,
                         const std::vector<PixelRays>& rays, double hidden_sigma_px,
                         std::mt19937_64& rng) {
  const Points3d& kp = frame->mesh.keypoints;
  const Eigen::Vector3d wrist = kp.row(0).transpose();
  const Eigen::Vector3d palm_normal =
      (kp.row(5).transpose() - wrist).cross(kp.row(17).transpose() - wrist).normalized();
  const Eigen::Vector3d fingers =
      (kp.row(6) + kp.row(7) + kp.row(10) + kp.row(11)).transpose() / 4.0;
  RenderMesh ball = MakeSphere(0.025);
  TransformMesh(Rigid3(Eigen::Quaterniond::Identity(), fingers + 0.02 * palm_normal),
                &ball);
  RenderMesh hand;
  hand.vertices = frame->mesh.vertices;
  hand.faces = model.faces;
  std::normal_distribution<double> g(0.0, hidden_sigma_px);
  HeldBall out;
  for (size_t v = 0; v < frame->views.size(); ++v) {
    KeypointView& view = frame->views[v];
    VisibilityBuffer buffer;
    buffer.Reset(rays[v].width(), rays[v].height());
    RasterizeMesh(hand, 0, view.camera.cam_from_world, rays[v], &buffer);
    RasterizeMesh(ball, 1, view.camera.cam_from_world, rays[v], &buffer);
    MaskImage hand_mask = MaskImage::Zero(rays[v].height(), rays[v].width());
    MaskImage ball_mask = hand_mask;
    for (int y = 0; y < rays[v].height(); ++y) {
      for (int x = 0; x < rays[v].width(); ++x) {
        const int id = buffer.mesh_id[buffer.index(x, y)];
        hand_mask(y, x) = id == 0 ? 255 : 0;
        ball_mask(y, x) = id == 1 ? 255 : 0;
      }
    }
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const Eigen::Vector2d uv = view.keypoints.uv_px.row(k).transpose();
      const int x = static_cast<int>(std::lround(uv.x()));
      const int y = static_cast<int>(std::lround(uv.y()));
      if (x < 0 || y < 0 || x >= rays[v].width() || y >= rays[v].height()) continue;
      const size_t i = buffer.index(x, y);
      const double z = (view.camera.cam_from_world * kp.row(k).transpose()).z();
      if (buffer.mesh_id[i] != 1 || !(buffer.depth[i] < z)) continue;
      view.keypoints.uv_px(k, 0) += g(rng);
      view.keypoints.uv_px(k, 1) += g(rng);
      view.keypoints.confidence[k] = std::min(view.keypoints.confidence[k], 0.3);
      ++out.hidden_keypoints;
    }
    out.hand_masks.push_back(std::move(hand_mask));
    out.occluder_masks.push_back(std::move(ball_mask));
  }
  return out;
}

}  // namespace handlabel::testing
