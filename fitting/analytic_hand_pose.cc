#include "fitting/analytic_hand_pose.h"

#include <Eigen/Geometry>
#include <array>

namespace handlabel {
namespace {

// Native+tips index of the point a joint's bone points to: the joint's child, or for
// the last joint of a finger its fingertip (tips 16-20: thumb, index, middle, ring,
// pinky).
constexpr std::array<int, kNumHandJoints> kBoneEnd = {-1, 2,  3,  17, 5,  6,  18, 8,
                                                      9,  20, 11, 12, 19, 14, 15, 16};

}  // namespace

void AnalyticHandPose(const Points3d& rest_keypoints, const Points3d& target_keypoints,
                      const Eigen::VectorXd& weights,
                      const Eigen::Matrix3d& root_rotation, double* pose45) {
  // SNAP order -> native+tips order.
  Eigen::Vector3d rest[kNumHandKeypoints], target[kNumHandKeypoints];
  bool known[kNumHandKeypoints];
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int n = kSnapFromNative[k];
    rest[n] = rest_keypoints.row(k).transpose();
    target[n] = target_keypoints.row(k).transpose();
    known[n] = weights[k] > 0.0;
  }
  Eigen::Matrix3d global[kNumHandJoints];
  global[0] = root_rotation;
  for (int j = 1; j < kNumHandJoints; ++j) {
    const Eigen::Matrix3d& parent = global[kManoParents[j]];
    const int end = kBoneEnd[j];
    Eigen::Matrix3d local = Eigen::Matrix3d::Identity();
    const Eigen::Vector3d rest_bone = rest[end] - rest[j];
    const Eigen::Vector3d target_bone = target[end] - target[j];
    if (known[j] && known[end] && rest_bone.norm() > 1e-9 && target_bone.norm() > 1e-9) {
      local =
          Eigen::Quaterniond::FromTwoVectors(rest_bone, parent.transpose() * target_bone)
              .toRotationMatrix();
    }
    global[j] = parent * local;
    const Eigen::AngleAxisd aa(local);
    const Eigen::Vector3d w = aa.angle() * aa.axis();
    for (int c = 0; c < 3; ++c) pose45[3 * (j - 1) + c] = w[c];
  }
}

}  // namespace handlabel
