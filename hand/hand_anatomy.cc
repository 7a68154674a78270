#include "hand/hand_anatomy.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Native chains (1-3, 4-6, 7-9, 10-12, 13-15) are index, middle, pinky, ring, thumb;
// entry = index into HandModel::tip_vertex_ids (thumb, index, middle, ring, pinky).
constexpr std::array<int, 5> kTipOfChain = {1, 2, 4, 3, 0};

int Chain(int joint) { return (joint - 1) / 3; }
int Level(int joint) { return (joint - 1) % 3; }

using Limits3 = std::array<AngleLimit, 3>;

Limits3 MakeLimits(double twist_min, double twist_max, double spread_min,
                   double spread_max, double bend_min, double bend_max) {
  return {AngleLimit{twist_min, twist_max}, AngleLimit{spread_min, spread_max},
          AngleLimit{bend_min, bend_max}};
}

HandLimits LimitsByType(const Limits3& thumb_cmc, const Limits3& thumb_mcp,
                        const Limits3& thumb_ip, const Limits3& finger_mcp,
                        const Limits3& finger_pip, const Limits3& finger_dip) {
  HandLimits limits;
  for (int j = 1; j < kNumHandJoints; ++j) {
    switch (JointType(j)) {
      case HandJointType::kThumbCmc:
        limits.joints[j] = thumb_cmc;
        break;
      case HandJointType::kThumbMcp:
        limits.joints[j] = thumb_mcp;
        break;
      case HandJointType::kThumbIp:
        limits.joints[j] = thumb_ip;
        break;
      case HandJointType::kFingerMcp:
        limits.joints[j] = finger_mcp;
        break;
      case HandJointType::kFingerPip:
        limits.joints[j] = finger_pip;
        break;
      case HandJointType::kFingerDip:
        limits.joints[j] = finger_dip;
        break;
      case HandJointType::kRoot:
        break;
    }
  }
  return limits;
}

}  // namespace

HandJointType JointType(int joint) {
  HL_CHECK(joint >= 0 && joint < kNumHandJoints, "joint " + std::to_string(joint));
  if (joint == 0) return HandJointType::kRoot;
  const bool thumb = Chain(joint) == 4;
  switch (Level(joint)) {
    case 0:
      return thumb ? HandJointType::kThumbCmc : HandJointType::kFingerMcp;
    case 1:
      return thumb ? HandJointType::kThumbMcp : HandJointType::kFingerPip;
    default:
      return thumb ? HandJointType::kThumbIp : HandJointType::kFingerDip;
  }
}

std::string JointName(int joint) {
  static const char* const kFingers[5] = {"index", "middle", "pinky", "ring", "thumb"};
  static const char* const kFingerLevels[3] = {"mcp", "pip", "dip"};
  static const char* const kThumbLevels[3] = {"cmc", "mcp", "ip"};
  if (joint == 0) return "wrist";
  const int chain = Chain(joint);
  return std::string(kFingers[chain]) + "_" +
         (chain == 4 ? kThumbLevels[Level(joint)] : kFingerLevels[Level(joint)]);
}

HandAnatomy ComputeHandAnatomy(const HandModel& model) {
  const std::string source = "hand model " + model.name;
  if (model.parents != kManoParents) {
    throw InputError(source, "kintree_table", "MANO's kinematic tree");
  }
  const Eigen::MatrixXd joints = model.joint_regressor * model.v_template;
  const bool left = model.side == HandSide::kLeft;
  HandAnatomy anatomy;
  anatomy.side = model.side;
  anatomy.angle_signs = left ? Eigen::Vector3d(-1, -1, 1) : Eigen::Vector3d(1, 1, 1);
  anatomy.frames[0].setIdentity();
  for (int j = 1; j < kNumHandJoints; ++j) {
    const Eigen::Vector3d joint = joints.row(j).transpose();
    const Eigen::Vector3d child =
        Level(j) < 2
            ? Eigen::Vector3d(joints.row(j + 1).transpose())
            : Eigen::Vector3d(
                  model.v_template.row(model.tip_vertex_ids[kTipOfChain[Chain(j)]])
                      .transpose());
    Eigen::Vector3d up =
        Chain(j) == 4 ? Eigen::Vector3d(1, 1, 1) : Eigen::Vector3d(0, 1, 0);
    if (left) up.x() = -up.x();
    const Eigen::Vector3d bone = joint - child;
    const double length = bone.norm();
    if (!(length > 1e-9)) {
      throw InputError(source, "rest joints",
                       "a bone of non-zero length at " + JointName(j),
                       std::to_string(length));
    }
    const Eigen::Vector3d b = bone / length;
    const Eigen::Vector3d l_raw = b.cross(up.normalized());
    // A bone nearly parallel to `up` means the model is not in MANO's layout.
    if (l_raw.norm() < 0.1) {
      throw InputError(
          source, "rest joints",
          "MANO layout (fingers along -x, back of the hand +y) at " + JointName(j),
          "bone direction (" + std::to_string(b.x()) + ", " + std::to_string(b.y()) +
              ", " + std::to_string(b.z()) + ")");
    }
    const Eigen::Vector3d l = l_raw.normalized();
    const Eigen::Vector3d u = l.cross(b);
    anatomy.frames[j].col(kTwist) = b;
    anatomy.frames[j].col(kSpread) = u;
    anatomy.frames[j].col(kBend) = l;
  }
  return anatomy;
}

Eigen::Vector3d AxisAngleFromAnatomicalAngles(const HandAnatomy& anatomy, int joint,
                                              const Eigen::Vector3d& angles) {
  const Eigen::Vector3d a = angles.cwiseProduct(anatomy.angle_signs);
  const Eigen::Matrix3d ra = (Eigen::AngleAxisd(a[kTwist], Eigen::Vector3d::UnitX()) *
                              Eigen::AngleAxisd(a[kSpread], Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(a[kBend], Eigen::Vector3d::UnitZ()))
                                 .toRotationMatrix();
  const Eigen::Matrix3d& f = anatomy.frames[joint];
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(f * ra * f.transpose()));
  return aa.angle() * aa.axis();
}

HandPoseVector HandPoseFromAnatomicalAngles(const HandAnatomy& anatomy,
                                            const HandPoseVector& angles45) {
  HandPoseVector pose;
  for (int j = 1; j < kNumHandJoints; ++j) {
    pose.segment<3>(3 * (j - 1)) =
        AxisAngleFromAnatomicalAngles(anatomy, j, angles45.segment<3>(3 * (j - 1)));
  }
  return pose;
}

void HandLimits::Check(const std::string& source) const {
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int a = 0; a < 3; ++a) {
      const AngleLimit& l = joints[j][a];
      if (!(l.min_deg <= l.max_deg)) {
        static const char* const kAxes[3] = {"twist", "spread", "bend"};
        throw InputError(source, JointName(j) + "." + kAxes[a], "min_deg <= max_deg",
                         std::to_string(l.min_deg) + " > " + std::to_string(l.max_deg));
      }
    }
  }
}

HandLimits AnchorHandLimits() {
  return LimitsByType(MakeLimits(-45, 45, -15, 45, 0, 45),  // thumb CMC
                      MakeLimits(0, 0, -10, 10, 0, 90),     // thumb MCP
                      MakeLimits(0, 0, 0, 0, 0, 90),        // thumb IP
                      MakeLimits(0, 0, -5, 5, 0, 90),       // finger MCP
                      MakeLimits(0, 0, 0, 0, 0, 90),        // finger PIP
                      MakeLimits(0, 0, 0, 0, 0, 90));       // finger DIP
}

HandLimits DefaultHandLimits() {
  return LimitsByType(MakeLimits(-45, 45, -15, 45, -15, 45),  // thumb CMC
                      MakeLimits(-8, 8, -10, 10, -10, 90),    // thumb MCP
                      MakeLimits(-8, 8, -8, 8, -15, 90),      // thumb IP
                      MakeLimits(-8, 8, -20, 20, -20, 90),    // finger MCP
                      MakeLimits(-8, 8, -8, 8, -5, 110),      // finger PIP
                      MakeLimits(-8, 8, -8, 8, -10, 90));     // finger DIP
}

double MaxLimitViolationDeg(const HandLimits& limits, const HandPoseVector& angles45,
                            int* worst) {
  double max_violation = 0.0;
  if (worst) *worst = -1;
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int a = 0; a < 3; ++a) {
      const int i = 3 * (j - 1) + a;
      const double deg = angles45[i] / kDeg;
      const double v = std::isfinite(deg)
                           ? std::max({0.0, deg - limits.joints[j][a].max_deg,
                                       limits.joints[j][a].min_deg - deg})
                           : HUGE_VAL;
      if (v > max_violation) {
        max_violation = v;
        if (worst) *worst = i;
      }
    }
  }
  return max_violation;
}

bool AnglesWithinLimits(const HandLimits& limits, const HandPoseVector& angles45,
                        double tolerance_deg) {
  return MaxLimitViolationDeg(limits, angles45) <= tolerance_deg;
}

}  // namespace handlabel
