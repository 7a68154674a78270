#include "capture/synth_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "image/mesh_primitives.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

HandPoseVector ClampToLimits(const HandAnatomy& anatomy, const HandLimits& limits,
                             const HandPoseVector& hand_pose) {
  HandPoseVector angles;
  HandAnatomicalAngles(anatomy, hand_pose.data(), angles.data());
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int a = 0; a < 3; ++a) {
      double& v = angles[3 * (j - 1) + a];
      v = std::clamp(v, limits.joints[j][a].min_deg * kDeg,
                     limits.joints[j][a].max_deg * kDeg);
    }
  }
  return HandPoseFromAnatomicalAngles(anatomy, angles);
}

// Pose of the requested kind (index into SynthPoseKindNames()).
HandPoseVector SamplePose(const HandModel& model, const HandAnatomy& anatomy,
                          const HandLimits& limits, const SynthSceneOptions& o, int kind,
                          std::mt19937_64& rng) {
  constexpr HandPoseKind kSampler[5] = {HandPoseKind::kOpen, HandPoseKind::kFist,
                                        HandPoseKind::kPinch, HandPoseKind::kPoint,
                                        HandPoseKind::kRandom};
  if (kind < 5) {
    return SampleHandPoseOfKind(anatomy, limits, kSampler[kind], o.jitter_deg, rng)
        .hand_pose;
  }
  if (kind == 5) {  // grasp: a partial fist
    const SampledHandPose fist =
        SampleHandPoseOfKind(anatomy, limits, HandPoseKind::kFist, o.jitter_deg, rng);
    const double t = Uniform(rng, 0.3, 0.75);
    return ClampToLimits(anatomy, limits,
                         HandPoseFromAnatomicalAngles(anatomy, t * fist.angles));
  }
  const int n = std::min<int>(o.pca_components, model.pose_pca_basis.rows());
  Eigen::VectorXd coeffs(n);
  for (int i = 0; i < n; ++i) coeffs[i] = Gaussian(rng, o.pca_sigma);
  return ClampToLimits(anatomy, limits, HandPoseFromPca(model, coeffs, false));
}

// Skin albedos from very light to very dark (linear-ish RGB in [0, 1]).
const float kSkinTones[][3] = {{0.96f, 0.80f, 0.69f}, {0.93f, 0.74f, 0.60f},
                               {0.86f, 0.65f, 0.52f}, {0.78f, 0.56f, 0.42f},
                               {0.64f, 0.44f, 0.31f}, {0.47f, 0.31f, 0.22f},
                               {0.34f, 0.23f, 0.17f}};

std::shared_ptr<const ImageU8> MakeObjectTexture(int kind, std::mt19937_64& rng) {
  auto tex = std::make_shared<ImageU8>(64, 64, 3);
  const int period = 4 + static_cast<int>(Uniform(rng, 0, 12));
  Eigen::Vector3f a(Uniform(rng, 0.2, 1), Uniform(rng, 0.2, 1), Uniform(rng, 0.2, 1));
  Eigen::Vector3f b = Eigen::Vector3f::Ones() - 0.7f * a;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const bool on =
          kind == 1 ? (x / period) % 2 == 0 : ((x / period) + (y / period)) % 2 == 0;
      const Eigen::Vector3f& c = on ? a : b;
      for (int ch = 0; ch < 3; ++ch)
        tex->at(x, y, ch) = static_cast<uint8_t>(255 * c[ch]);
    }
  }
  return tex;
}

}  // namespace

Eigen::Quaterniond UniformRandomRotation(std::mt19937_64& rng) {
  Eigen::Vector4d q;
  for (int i = 0; i < 4; ++i) q[i] = Gaussian(rng, 1.0);
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
}

Eigen::Vector3d RandomPointInBall(std::mt19937_64& rng, double radius) {
  for (;;) {
    const Eigen::Vector3d p(Uniform(rng, -1, 1), Uniform(rng, -1, 1),
                            Uniform(rng, -1, 1));
    if (p.squaredNorm() <= 1.0) return radius * p;
  }
}

SynthObject SampleSynthObject(const Eigen::Vector3d& anchor, const Eigen::Vector3d& away,
                              std::mt19937_64& rng) {
  SynthObject obj;
  const int kind = static_cast<int>(Uniform(rng, 0, 3));
  double half = 0;  // extent along `away`, to keep the object just off the skin
  if (kind == 0) {
    const double r = Uniform(rng, 0.02, 0.045);
    obj.kind = "sphere";
    obj.size = Eigen::Vector3d(r, r, r);
    half = r;
  } else if (kind == 1) {
    obj.kind = "box";
    obj.size = Eigen::Vector3d(Uniform(rng, 0.025, 0.09), Uniform(rng, 0.025, 0.09),
                               Uniform(rng, 0.025, 0.09));
    half = 0.5 * obj.size.minCoeff();
  } else {
    const double r = Uniform(rng, 0.015, 0.04);
    obj.kind = "cylinder";
    obj.size = Eigen::Vector3d(r, r, Uniform(rng, 0.06, 0.16));
    half = r;
  }
  obj.mesh = MakeObjectMesh(obj.kind, obj.size);
  obj.world_from_object = Rigid3(UniformRandomRotation(rng),
                                 anchor + (half + Uniform(rng, 0.0, 0.01)) * away);
  TransformMesh(obj.world_from_object, &obj.mesh);
  obj.color =
      Eigen::Vector3f(Uniform(rng, 0.1, 1), Uniform(rng, 0.1, 1), Uniform(rng, 0.1, 1));
  obj.mesh.color = obj.color;
  obj.texture_kind = static_cast<int>(Uniform(rng, 0, 3));
  if (obj.texture_kind > 0) {
    obj.mesh.texture = MakeObjectTexture(obj.texture_kind, rng);
  }
  return obj;
}

int CamerasSeeingAll(const Rig& rig, const Points3d& points) {
  int count = 0;
  for (const RigCamera& cam : rig.cameras()) {
    bool all = true;
    for (Eigen::Index i = 0; i < points.rows() && all; ++i) {
      Eigen::Vector2d uv;
      const Eigen::Vector3d p = cam.cam_from_world * Eigen::Vector3d(points.row(i));
      all = p.z() > 0.05 && cam.camera.Project(p, &uv) && cam.camera.InImage(uv, 2.0);
    }
    count += all;
  }
  return count;
}

RenderMesh MakeObjectMesh(const std::string& kind, const Eigen::Vector3d& size) {
  if (!(size.array() > 0).all()) {
    throw InputError("object", "size", "positive sizes", "");
  }
  if (kind == "sphere") return MakeSphere(size.x(), 16, 24);
  if (kind == "box") return MakeBox(size, 4);
  if (kind == "cylinder") return MakeCylinder(size.x(), size.z(), 24, 4);
  throw InputError("object", "kind", "sphere, box or cylinder", kind);
}

void SynthSceneOptions::Check(const std::string& source) const {
  const double w[] = {weight_open,   weight_fist,  weight_pinch, weight_point,
                      weight_random, weight_grasp, weight_pca};
  double total = 0;
  for (double x : w) {
    RequireAtLeast(source, "weight_*", x, 0);
    total += x;
  }
  if (!(total > 0)) throw InputError(source, "weight_*", "at least one weight > 0");
  RequireInRange(source, "jitter_deg", jitter_deg, 0, 45);
  if (!(pca_sigma >= 0) || pca_components < 1) {
    throw InputError(source, "pca_sigma/pca_components", "sigma >= 0 and >= 1 component");
  }
  RequireInRange(source, "betas_sigma", betas_sigma, 0, 5);
  RequireInRange(source, "object_probability", object_probability, 0, 1);
  RequireInRange(source, "max_objects", max_objects, 1, 8);
  if (!(workspace_radius >= 0) || !workspace_center.allFinite()) {
    throw InputError(source, "workspace_radius/center", "finite, radius >= 0");
  }
  RequireAtLeast(source, "placement_tries", placement_tries, 1);
}

std::vector<std::string> SynthPoseKindNames() {
  return {"open", "fist", "pinch", "point", "random", "grasp", "pca"};
}

HandPoseVector SampleSynthPose(const HandModel& model, const HandAnatomy& anatomy,
                               const HandLimits& limits, const SynthSceneOptions& options,
                               const std::string& kind, std::mt19937_64& rng) {
  const std::vector<std::string> names = SynthPoseKindNames();
  const auto it = std::find(names.begin(), names.end(), kind);
  if (it == names.end()) {
    throw InputError("synthetic scene", "pose kind",
                     "open, fist, pinch, point, random, grasp or pca", kind);
  }
  return SamplePose(model, anatomy, limits, options, static_cast<int>(it - names.begin()),
                    rng);
}

Eigen::VectorXd SampleSynthBetas(const HandModel& model, const SynthSceneOptions& o,
                                 std::mt19937_64& rng) {
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(std::min(model.num_betas(), 10));
  for (Eigen::Index i = 0; i < betas.size(); ++i) {
    betas[i] = std::clamp(Gaussian(rng, o.betas_sigma), -2.5 * o.betas_sigma,
                          2.5 * o.betas_sigma);
  }
  return betas;
}

void HeldObjectAnchor(const HandParams& params, const Points3d& k,
                      const std::string& pose_kind, Eigen::Vector3d* anchor,
                      Eigen::Vector3d* away) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(params.global_orient.norm(),
                                              params.global_orient.norm() > 0
                                                  ? params.global_orient.normalized()
                                                  : Eigen::Vector3d::UnitX())
                                .toRotationMatrix();
  const Eigen::Vector3d palm_normal = r * Eigen::Vector3d(0, -1, 0);
  const Eigen::Vector3d palm_centre =
      (k.row(0) + k.row(5) + k.row(9) + k.row(13) + k.row(17)).transpose() / 5.0;
  if (pose_kind == "pinch") {
    // Held at the pinching tips, on the side away from the palm (not swallowing the
    // fingertips).
    *anchor = 0.5 * (k.row(4) + k.row(8)).transpose();
    *away = (*anchor - palm_centre).normalized();
  } else {
    *anchor = palm_centre + 0.01 * palm_normal;
    *away = palm_normal;
  }
}

namespace {

// Pose kind, pose and shape; objects make grasps more likely, as in hand-object
// datasets.
void SamplePoseAndShape(const HandModel& model, const HandAnatomy& anatomy,
                        const HandLimits& limits, const SynthSceneOptions& o,
                        std::mt19937_64& rng, SynthScene* scene) {
  const double grasp_boost = o.objects ? 2.0 : 1.0;
  std::discrete_distribution<int> pick({o.weight_open, o.weight_fist, o.weight_pinch,
                                        o.weight_point, o.weight_random,
                                        o.weight_grasp * grasp_boost, o.weight_pca});
  const int kind = pick(rng);
  scene->pose_kind = SynthPoseKindNames()[kind];
  HandParams& params = scene->params;
  params.hand_pose = SamplePose(model, anatomy, limits, o, kind, rng);
  params.betas = SampleSynthBetas(model, o, rng);
}

// Placement: the hand at rest orientation, then rotated about the wrist (as the root
// rotation does) and moved; keeps the try that the most cameras see entirely (sets
// global_orient and transl) and returns that number of cameras.
int PlaceHand(const HandModel& model, const Rig& rig, const SynthSceneOptions& o,
              std::mt19937_64& rng, HandParams* params) {
  const HandMesh rest = PoseHand(model, *params);
  const Eigen::RowVector3d wrist = rest.joints.row(0);
  const Eigen::RowVector3d centre = rest.keypoints.colwise().mean();
  int best = -1;
  for (int t = 0; t < o.placement_tries; ++t) {
    const Eigen::Quaterniond q = UniformRandomRotation(rng);
    const Eigen::Vector3d target =
        o.workspace_center + RandomPointInBall(rng, o.workspace_radius);
    const Eigen::Matrix3d r = q.toRotationMatrix();
    // keypoint' = R (k - wrist) + wrist + transl; centre' = target.
    const Eigen::Vector3d transl =
        target - (r * (centre - wrist).transpose() + wrist.transpose());
    Points3d kp(rest.keypoints.rows(), 3);
    for (Eigen::Index i = 0; i < kp.rows(); ++i) {
      kp.row(i) =
          (r * (rest.keypoints.row(i) - wrist).transpose() + wrist.transpose() + transl)
              .transpose();
    }
    const int seen = CamerasSeeingAll(rig, kp);
    if (seen > best) {
      best = seen;
      const Eigen::AngleAxisd aa(q);
      params->global_orient = aa.angle() * aa.axis();
      params->transl = transl;
    }
    if (best == static_cast<int>(rig.size())) break;
  }
  return best;
}

}  // namespace

void SampleSynthAppearance(const HandModel& model, std::mt19937_64& rng,
                           SynthScene* scene) {
  const float* tone = kSkinTones[static_cast<int>(Uniform(rng, 0, 7))];
  for (int c = 0; c < 3; ++c) {
    scene->skin[c] =
        std::clamp(tone[c] * static_cast<float>(Uniform(rng, 0.93, 1.07)), 0.0f, 1.0f);
  }
  RenderMesh& hand = scene->hand_render;
  hand.vertices = scene->hand.vertices;
  hand.faces = model.faces;
  hand.normals = ComputeVertexNormals(hand.vertices, hand.faces);
  hand.colors.resize(hand.vertices.rows(), 3);
  for (Eigen::Index v = 0; v < hand.colors.rows(); ++v) {
    const float shade = static_cast<float>(Uniform(rng, 0.95, 1.05));
    hand.colors.row(v) = (shade * scene->skin).cwiseMin(1.0f).transpose();
  }
  scene->lighting.ambient =
      Eigen::Vector3f::Constant(static_cast<float>(Uniform(rng, 0.25, 0.5)));
  const int num_lights = 1 + static_cast<int>(Uniform(rng, 0, 2));
  scene->lighting.lights.clear();
  for (int l = 0; l < num_lights; ++l) {
    // Light from above: the direction of travel points downwards.
    Eigen::Vector3d from(Gaussian(rng, 1), Gaussian(rng, 1),
                         std::abs(Gaussian(rng, 1)) + 0.3);
    DirectionalLight light;
    light.direction_in_world = -from.normalized();
    const float intensity = static_cast<float>(Uniform(rng, 0.4, 0.8)) / num_lights;
    light.color =
        intensity * Eigen::Vector3f(static_cast<float>(Uniform(rng, 0.9, 1.1)), 1.0f,
                                    static_cast<float>(Uniform(rng, 0.9, 1.1)));
    scene->lighting.lights.push_back(light);
  }
}

namespace {

// Objects: the first one in the hand (in front of the palm, or at the thumb and index
// tips for pinches), the others nearby.
void AddObjects(const SynthSceneOptions& o, std::mt19937_64& rng, SynthScene* scene) {
  const int count = 1 + static_cast<int>(Uniform(rng, 0, o.max_objects));
  const Points3d& k = scene->hand.keypoints;
  const Eigen::Vector3d palm_centre =
      (k.row(0) + k.row(5) + k.row(9) + k.row(13) + k.row(17)).transpose() / 5.0;
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d anchor, away;
    if (i == 0) {
      HeldObjectAnchor(scene->params, k, scene->pose_kind, &anchor, &away);
    } else {
      away = RandomPointInBall(rng, 1.0).normalized();
      anchor = palm_centre + Uniform(rng, 0.05, 0.12) * away;
    }
    scene->objects.push_back(SampleSynthObject(anchor, away, rng));
  }
}

}  // namespace

SynthScene SampleSynthScene(const HandModel& model, const HandAnatomy& anatomy,
                            const HandLimits& limits, const Rig& rig,
                            const SynthSceneOptions& o, std::mt19937_64& rng) {
  SynthScene scene;
  scene.side = model.side;
  SamplePoseAndShape(model, anatomy, limits, o, rng, &scene);
  scene.cameras_seeing_hand = PlaceHand(model, rig, o, rng, &scene.params);
  scene.hand = PoseHand(model, scene.params);
  SampleSynthAppearance(model, rng, &scene);
  const bool with_objects = o.objects && (o.object_probability >= 1.0 ||
                                          Uniform(rng, 0, 1) < o.object_probability);
  if (with_objects) AddObjects(o, rng, &scene);
  return scene;
}

}  // namespace handlabel
