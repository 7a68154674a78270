#pragma once
// Anatomical joint frames, (twist, spread, bend) angles and joint limits of a
// MANO-structured hand (CPF / manotorch style), for pose priors in fitting and for
// sampling natural poses in synthetic data.
//
// Frame of non-root joint j, from the model's rest joints (betas = 0):
//   b = normalize(J_j - C_j)     twist axis: along the joint's outgoing bone, pointing
//                                back towards the joint (C_j = child joint, or the
//                                finger's tip vertex for the last joint of a chain)
//   l = normalize(b x up)        bend axis
//   u = l x b                    spread axis
//   up = (0, 1, 0) for fingers, (1, 1, 1) for the thumb; the left hand mirrors x:
//   (-1, 1, 1). MANO layout: fingers along -x, back of the hand +y, thumb +z, so for the
//   right hand b ~ +x, l ~ +z, u ~ +y and flexion (towards the palm, -y) is a positive
//   bend. hand-model.md writes b as child - joint; we keep manotorch's "back" direction
//   because with child - joint, l flips and flexion would come out negative, contrary
//   to the +90/0 bend limits.
// Angles: with F = [b u l] (columns) and R the joint's local rotation (axis-angle of
// hand_pose), the rotation in the anatomical frame Ra = F^T R F is decomposed as
// intrinsic X-Y'-Z'' Euler angles (pytorch3d convention "XYZ"):
//   Ra = Rx(twist) * Ry(spread) * Rz(bend)      (x = b, y = u, z = l)
//   spread = atan2(Ra02, hypot(Ra00, Ra01)), twist = atan2(-Ra12, Ra22),
//   bend = atan2(-Ra01, Ra00); unique for |spread| < 90 deg.
// Left hand: its frames are the mirror images made right-handed, so a mirrored motion
// turns the other way about b and u; twist and spread are negated (angle_signs) so
// that mirrored poses of the two hands have identical angles and one limits table
// serves both sides.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <string>
#include <type_traits>

#include "geometry/axis_angle.h"
#include "geometry/dual.h"
#include "geometry/scalar_ops.h"
#include "hand/hand_model.h"

namespace handlabel {

using HandPoseVector = Eigen::Matrix<double, kNumPoseParams, 1>;

enum AnatomicalAxis : int { kTwist = 0, kSpread = 1, kBend = 2 };

enum class HandJointType {
  kRoot,
  kThumbCmc,
  kThumbMcp,
  kThumbIp,
  kFingerMcp,
  kFingerPip,
  kFingerDip
};
// Type of native joint j (0..15).
HandJointType JointType(int joint);
// Human-readable joint name, e.g. "index_pip", "thumb_cmc".
std::string JointName(int joint);

struct HandAnatomy {
  HandSide side = HandSide::kRight;
  // Rest frame of native joint j as columns (b, u, l) in model coordinates;
  // frames[0] (root, unconstrained) is the identity.
  std::array<Eigen::Matrix3d, kNumHandJoints> frames;
  // Multiplies (twist, spread, bend): (1, 1, 1) right hand, (-1, -1, 1) left hand.
  Eigen::Vector3d angle_signs = Eigen::Vector3d::Ones();
};

// Frames from the model's rest joints and tip vertices. Throws InputError when a bone
// is degenerate or parallel to its up vector (not a MANO-like layout).
HandAnatomy ComputeHandAnatomy(const HandModel& model);

// (twist, spread, bend) in radians of non-root joint `joint` from its axis-angle.
// Plain scalar evaluation; AnatomicalAngles below is the one to call.
template <typename T>
void AnatomicalAnglesDirect(const HandAnatomy& anatomy, int joint, const T* axis_angle,
                            T* angles) {
  using std::atan2;
  using std::sqrt;
  T r[9];
  AxisAngleToRotation(axis_angle, r);
  const Eigen::Matrix3d& f = anatomy.frames[joint];
  // m = R F, then ra = F^T m; only five entries of ra are needed.
  T m[9];
  for (int i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) {
      m[3 * i + c] = r[3 * i] * f(0, c) + r[3 * i + 1] * f(1, c) + r[3 * i + 2] * f(2, c);
    }
  }
  auto ra = [&](int i, int c) {
    return f(0, i) * m[c] + f(1, i) * m[3 + c] + f(2, i) * m[6 + c];
  };
  const T ra00 = ra(0, 0), ra01 = ra(0, 1), ra02 = ra(0, 2);
  const T ra12 = ra(1, 2), ra22 = ra(2, 2);
  const T twist = atan2(-ra12, ra22);
  const T spread = atan2(ra02, sqrt(ra00 * ra00 + ra01 * ra01));
  const T bend = atan2(-ra01, ra00);
  angles[kTwist] = twist * anatomy.angle_signs[kTwist];
  angles[kSpread] = spread * anatomy.angle_signs[kSpread];
  angles[kBend] = bend * anatomy.angle_signs[kBend];
}

// (twist, spread, bend) in radians of non-root joint `joint` from its axis-angle, for
// double, Dual<N> or ceres::Jet. For dual types the 3 angles depend on 3 inputs only,
// so they are evaluated with Dual<3> and chained into T (exact for first-order duals,
// about 10x cheaper than evaluating with 61-wide Jets).
template <typename T>
void AnatomicalAngles(const HandAnatomy& anatomy, int joint, const T* axis_angle,
                      T* angles) {
  if constexpr (std::is_same_v<T, double>) {
    AnatomicalAnglesDirect(anatomy, joint, axis_angle, angles);
  } else {
    Dual<3> w[3], a[3];
    for (int i = 0; i < 3; ++i) w[i] = Dual<3>(ScalarPart(axis_angle[i]), i);
    AnatomicalAnglesDirect(anatomy, joint, w, a);
    for (int k = 0; k < 3; ++k) {
      T out = T(a[k].a);
      for (int i = 0; i < 3; ++i) {
        AddScaled(a[k].v[i], axis_angle[i] - ScalarPart(axis_angle[i]), &out);
      }
      angles[k] = out;
    }
  }
}

// Angles of all 15 non-root joints: angles45[3 * (j - 1) + axis].
template <typename T>
void HandAnatomicalAngles(const HandAnatomy& anatomy, const T* hand_pose45, T* angles45) {
  for (int j = 1; j < kNumHandJoints; ++j) {
    AnatomicalAngles(anatomy, j, hand_pose45 + 3 * (j - 1), angles45 + 3 * (j - 1));
  }
}

// Inverse of AnatomicalAngles (doubles): axis-angle of joint `joint`.
Eigen::Vector3d AxisAngleFromAnatomicalAngles(const HandAnatomy& anatomy, int joint,
                                              const Eigen::Vector3d& angles);
// hand_pose (45 axis-angle) from 45 anatomical angles (radians).
HandPoseVector HandPoseFromAnatomicalAngles(const HandAnatomy& anatomy,
                                            const HandPoseVector& angles45);

// ---------------------------------------------------------------------------------
// Limits.

struct AngleLimit {
  double min_deg = 0.0;  // most negative allowed angle
  double max_deg = 0.0;  // most positive allowed angle
};

struct HandLimits {
  // joints[j][axis] for native joint j; joints[0] (root) is unused.
  std::array<std::array<AngleLimit, 3>, kNumHandJoints> joints{};
  // Throws InputError (naming `source`) if some min > max.
  void Check(const std::string& source) const;
};

// The table of hand-model.md verbatim (CPF / manotorch defaults).
HandLimits AnchorHandLimits();
// Our tuned defaults (degrees; reasons in docs/hand-model.md, "Anatomy"):
//   joint        twist   spread      bend
//   thumb CMC    +-45    -15/+45     -15/+45
//   thumb MCP    +-8     +-10        -10/+90
//   thumb IP     +-8     +-8         -15/+90
//   finger MCP   +-8     +-20        -20/+90
//   finger PIP   +-8     +-8          -5/+110
//   finger DIP   +-8     +-8         -10/+90
HandLimits DefaultHandLimits();

// Hinge residuals in radians: max(0, a - max) + max(0, min - a) per angle, zero inside
// the limits; residuals45[3 * (j - 1) + axis]. Templated for autodiff.
template <typename T>
void LimitResiduals(const HandLimits& limits, const T* angles45, T* residuals45) {
  constexpr double kRad = 3.14159265358979323846 / 180.0;
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int a = 0; a < 3; ++a) {
      const int i = 3 * (j - 1) + a;
      const double lo = limits.joints[j][a].min_deg * kRad;
      const double hi = limits.joints[j][a].max_deg * kRad;
      if (angles45[i] > T(hi)) {
        residuals45[i] = angles45[i] - hi;
      } else if (angles45[i] < T(lo)) {
        residuals45[i] = lo - angles45[i];
      } else {
        residuals45[i] = T(0.0);
      }
    }
  }
}

// True if every angle (radians) is within its limits up to tolerance_deg.
bool AnglesWithinLimits(const HandLimits& limits, const HandPoseVector& angles45,
                        double tolerance_deg = 1e-6);
// Largest violation in degrees (0 when within limits); `worst` (optional) gets the
// index 3 * (j - 1) + axis of the worst angle.
double MaxLimitViolationDeg(const HandLimits& limits, const HandPoseVector& angles45,
                            int* worst = nullptr);

}  // namespace handlabel
