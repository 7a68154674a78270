#include "exports/gltf_animation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <numeric>

#include "core/errors.h"
#include "core/option_checks.h"
#include "exports/glb_builder.h"
#include "hand/hand_anatomy.h"
#include "hand/shaped_hand.h"

namespace handlabel {
namespace {

using Affine = Eigen::Transform<double, 3, Eigen::Affine>;
constexpr int kInfluences = 4;      // joints per vertex: glTF's JOINTS_0 / WEIGHTS_0
constexpr int kFirstJointNode = 2;  // nodes: 0 root, 1 mesh, 2.. joints

// One keyframe: each joint's local rotation and translation, and their world transforms.
struct JointPose {
  std::array<Eigen::Quaterniond, kNumHandJoints> rotation;
  std::array<Eigen::Vector3d, kNumHandJoints> translation;
  std::array<Affine, kNumHandJoints> world;
};

Eigen::Quaterniond AxisAngleQuaternion(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle));
}

JointPose PoseJoints(const HandModel& model, const HandParams& params) {
  const Points3d rest = ShapeHand(model, params.betas).joints;
  JointPose pose;
  for (int j = 0; j < kNumHandJoints; ++j) {
    const int parent = model.parents[j];
    pose.rotation[j] = AxisAngleQuaternion(
        j == 0 ? params.global_orient
               : Eigen::Vector3d(params.hand_pose.segment<3>(3 * (j - 1))));
    pose.translation[j] =
        parent < 0 ? Eigen::Vector3d(rest.row(j).transpose() + params.transl)
                   : Eigen::Vector3d((rest.row(j) - rest.row(parent)).transpose());
    Affine local = Affine::Identity();
    local.translate(pose.translation[j]).rotate(pose.rotation[j]);
    pose.world[j] = parent < 0 ? local : pose.world[parent] * local;
  }
  return pose;
}

// The model's 4 largest weights per vertex, renormalised: (joint, weight) pairs.
struct Skin {
  std::vector<std::array<int, kInfluences>> joints;
  std::vector<std::array<double, kInfluences>> weights;
};

Skin TopWeights(const HandModel& model) {
  Skin skin;
  for (int v = 0; v < model.num_vertices(); ++v) {
    std::array<int, kNumHandJoints> order;
    std::iota(order.begin(), order.end(), 0);
    std::partial_sort(
        order.begin(), order.begin() + kInfluences, order.end(), [&](int a, int b) {
          return model.skinning_weights(v, a) > model.skinning_weights(v, b);
        });
    std::array<int, kInfluences> joints;
    std::array<double, kInfluences> weights;
    double sum = 0;
    for (int k = 0; k < kInfluences; ++k) {
      joints[k] = order[k];
      weights[k] = std::max(0.0, model.skinning_weights(v, order[k]));
      sum += weights[k];
    }
    if (sum <= 0)
      throw InputError(model.name, "weights", "some positive weight per vertex");
    for (double& w : weights) w /= sum;
    skin.joints.push_back(joints);
    skin.weights.push_back(weights);
  }
  return skin;
}

// Morph offsets (bind space) that make skinning of bind + offset land on `target`.
std::vector<float> CorrectiveTarget(const Skin& skin, const JointPose& pose,
                                    const Points3d& bind, const Points3d& bind_joints,
                                    const Points3d& target, const std::string& source) {
  std::vector<float> offsets;
  for (int v = 0; v < bind.rows(); ++v) {
    Eigen::Matrix<double, 3, 4> blended = Eigen::Matrix<double, 3, 4>::Zero();
    for (int k = 0; k < kInfluences; ++k) {
      const int j = skin.joints[v][k];
      Affine inverse_bind = Affine::Identity();
      inverse_bind.translate(-Eigen::Vector3d(bind_joints.row(j).transpose()));
      blended +=
          skin.weights[v][k] * (pose.world[j] * inverse_bind).matrix().topRows<3>();
    }
    const Eigen::Matrix3d linear = blended.leftCols<3>();
    if (std::abs(linear.determinant()) < 1e-6) {
      throw InputError(source, "vertices", "a pose the skin can carry",
                       "a degenerate blend at vertex " + std::to_string(v));
    }
    const Eigen::Vector3d rest =
        linear.inverse() * (target.row(v).transpose() - blended.col(3));
    for (int c = 0; c < 3; ++c)
      offsets.push_back(static_cast<float>(rest[c] - bind(v, c)));
  }
  return offsets;
}

std::vector<float> Floats(const Points3d& points) {
  std::vector<float> out;
  for (int r = 0; r < points.rows(); ++r)
    for (int c = 0; c < 3; ++c) out.push_back(static_cast<float>(points(r, c)));
  return out;
}

// The mesh: bind positions, skin attributes, triangles and one morph target per label.
void AddMesh(const HandModel& model, const ShapedHand& bind, const Skin& skin,
             const std::vector<int>& targets, const LabelSeries& series,
             GlbBuilder* glb) {
  std::vector<uint16_t> joints;
  std::vector<float> weights;
  for (size_t v = 0; v < skin.joints.size(); ++v) {
    for (int k = 0; k < kInfluences; ++k) {
      // glTF wants joint 0 wherever the weight is 0.
      const bool used = skin.weights[v][k] > 0;
      joints.push_back(static_cast<uint16_t>(used ? skin.joints[v][k] : 0));
      weights.push_back(static_cast<float>(skin.weights[v][k]));
    }
  }
  std::vector<uint32_t> indices(model.faces.data(),
                                model.faces.data() + model.faces.size());
  nlohmann::json attributes = {
      {"POSITION",
       glb->AddFloats(Floats(bind.vertices), "VEC3", GlbBuilder::kArrayBuffer)},
      {"JOINTS_0", glb->AddUnsignedShorts(joints, "VEC4", GlbBuilder::kArrayBuffer)},
      {"WEIGHTS_0", glb->AddFloats(weights, "VEC4", GlbBuilder::kArrayBuffer)}};
  nlohmann::json morphs = nlohmann::json::array(), names = nlohmann::json::array();
  for (size_t i = 0; i < targets.size(); ++i) {
    morphs.push_back({{"POSITION", targets[i]}});
    names.push_back(series.labels[i].frame);
  }
  nlohmann::json primitive = {
      {"attributes", attributes},
      {"indices",
       glb->AddUnsignedInts(indices, "SCALAR", GlbBuilder::kElementArrayBuffer)},
      {"targets", morphs}};
  glb->json()["meshes"] = {{{"name", model.name},
                            {"primitives", {primitive}},
                            {"weights", std::vector<double>(targets.size(), 0.0)},
                            {"extras", {{"targetNames", names}}}}};
}

// Nodes 0 (root of the joints), 1 (the skinned mesh), 2.. (the joints in the bind
// pose) and the skin.
void AddSkeleton(const HandModel& model, const ShapedHand& bind, GlbBuilder* glb) {
  // The skinned mesh is a root node: glTF ignores its parents' transforms anyway.
  nlohmann::json nodes = {{{"name", "hand"}, {"children", {kFirstJointNode}}},
                          {{"name", "hand_mesh"}, {"mesh", 0}, {"skin", 0}}};
  std::vector<float> inverse_binds;
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 0; j < kNumHandJoints; ++j) {
    const int parent = model.parents[j];
    const Eigen::Vector3d at = bind.joints.row(j).transpose();
    const Eigen::Vector3d local =
        parent < 0 ? at : Eigen::Vector3d(at - bind.joints.row(parent).transpose());
    nlohmann::json node = {{"name", JointName(j)},
                           {"translation", {local.x(), local.y(), local.z()}}};
    nlohmann::json children = nlohmann::json::array();
    for (int c = 0; c < kNumHandJoints; ++c) {
      if (model.parents[c] == j) children.push_back(kFirstJointNode + c);
    }
    if (!children.empty()) node["children"] = children;
    nodes.push_back(node);
    joints.push_back(kFirstJointNode + j);
    // Column-major 4x4 translation by -J_j (the joint's bind position).
    const float column_major[16] = {1,
                                    0,
                                    0,
                                    0,
                                    0,
                                    1,
                                    0,
                                    0,
                                    0,
                                    0,
                                    1,
                                    0,
                                    static_cast<float>(-at.x()),
                                    static_cast<float>(-at.y()),
                                    static_cast<float>(-at.z()),
                                    1};
    inverse_binds.insert(inverse_binds.end(), column_major, column_major + 16);
  }
  glb->json()["nodes"] = nodes;
  glb->json()["skins"] = {
      {{"joints", joints},
       {"skeleton", kFirstJointNode},
       {"inverseBindMatrices",
        glb->AddFloats(inverse_binds, "MAT4", GlbBuilder::kNoTarget)}}};
  glb->json()["scenes"] = {{{"nodes", {0, 1}}}};
  glb->json()["scene"] = 0;
}

// One animation: joint rotations and translations (LINEAR) and the morph weights that
// switch on each label's target at its keyframe (STEP).
void AddAnimation(const std::vector<JointPose>& poses, double fps, GlbBuilder* glb) {
  const size_t n = poses.size();
  std::vector<float> times, weights(n * n, 0.0f);
  for (size_t k = 0; k < n; ++k) {
    times.push_back(static_cast<float>(k / fps));
    weights[k * n + k] = 1.0f;
  }
  const int input = glb->AddFloats(times, "SCALAR", GlbBuilder::kNoTarget);
  nlohmann::json samplers = nlohmann::json::array(), channels = nlohmann::json::array();
  const auto add = [&](int output, const char* interpolation, int node,
                       const char* path) {
    channels.push_back(
        {{"sampler", samplers.size()}, {"target", {{"node", node}, {"path", path}}}});
    samplers.push_back(
        {{"input", input}, {"output", output}, {"interpolation", interpolation}});
  };
  for (int j = 0; j < kNumHandJoints; ++j) {
    std::vector<float> rotations, translations;
    Eigen::Quaterniond previous = Eigen::Quaterniond::Identity();
    for (size_t k = 0; k < n; ++k) {
      Eigen::Quaterniond q = poses[k].rotation[j];
      if (k > 0 && q.dot(previous) < 0) q.coeffs() *= -1;  // the short way between keys
      previous = q;
      for (int c = 0; c < 4; ++c) rotations.push_back(static_cast<float>(q.coeffs()[c]));
      for (int c = 0; c < 3; ++c)
        translations.push_back(static_cast<float>(poses[k].translation[j][c]));
    }
    add(glb->AddFloats(rotations, "VEC4", GlbBuilder::kNoTarget), "LINEAR",
        kFirstJointNode + j, "rotation");
    add(glb->AddFloats(translations, "VEC3", GlbBuilder::kNoTarget), "LINEAR",
        kFirstJointNode + j, "translation");
  }
  add(glb->AddFloats(weights, "SCALAR", GlbBuilder::kNoTarget), "STEP", 1, "weights");
  glb->json()["animations"] = {
      {{"name", "labels"}, {"samplers", samplers}, {"channels", channels}}};
}

}  // namespace

void GltfAnimationOptions::Check(const std::string& source) const {
  RequireGreater(source, "fps", fps, 0.0);
}

std::string HandAnimationGlb(const LabelSeries& series, const HandModel& model,
                             const GltfAnimationOptions& options) {
  options.Check("--fps");
  for (const LabelRecord& label : series.labels) {
    const std::string file = series.FileOf(label.frame);
    if (!label.params)
      throw InputError(file, "mano", "MANO parameters (a fitted label)", "null");
    if (label.mesh.vertices.rows() != model.num_vertices()) {
      throw InputError(file, "vertices",
                       std::to_string(model.num_vertices()) + " (the hand model's)",
                       std::to_string(label.mesh.vertices.rows()));
    }
  }
  const ShapedHand bind = ShapeHand(model, series.labels.front().params->betas);
  const Skin skin = TopWeights(model);
  GlbBuilder glb;
  std::vector<JointPose> poses;
  std::vector<int> targets;
  for (const LabelRecord& label : series.labels) {
    poses.push_back(PoseJoints(model, *label.params));
    targets.push_back(
        glb.AddFloats(CorrectiveTarget(skin, poses.back(), bind.vertices, bind.joints,
                                       label.mesh.vertices, series.FileOf(label.frame)),
                      "VEC3", GlbBuilder::kArrayBuffer));
  }
  AddMesh(model, bind, skin, targets, series, &glb);
  AddSkeleton(model, bind, &glb);
  AddAnimation(poses, options.fps, &glb);
  glb.json()["extras"] = {{"handlabel",
                           {{"labels", series.labels_dir},
                            {"frames", series.labels.size()},
                            {"fps", options.fps},
                            {"hand_side", HandSideName(series.side)},
                            {"hand_model", series.hand_model},
                            {"units", "m"},
                            {"frame", "the rig's world frame (no +Y up turn)"}}}};
  return glb.Finish();
}

}  // namespace handlabel
