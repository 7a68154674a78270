#pragma once
// Random scenes for synthetic captures: a posed hand (natural poses within anatomical
// limits, random shape), its skin tone, the lighting, and objects held near or in the
// hand, placed in a rig's world frame where most cameras see the hand.
//
// Pose kinds: the sampler's archetypes (open, fist, pinch, point, random within
// limits; hand/hand_pose_sampler.h), plus "grasp" (a partial fist, t in [0.3, 0.75] of
// the fist angles, as when holding an object) and "pca" (Gaussian coefficients on the
// model's pose PCA basis, clamped to the limits). Every pose is clamped to the limits.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "geometry/rig.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_lbs.h"
#include "hand/hand_model.h"
#include "hand/hand_pose_sampler.h"
#include "image/rasterizer.h"

namespace handlabel {

struct SynthSceneOptions {
  // Relative frequencies of the pose kinds (>= 0, not all zero).
  double weight_open = 1.0;
  double weight_fist = 0.7;
  double weight_pinch = 1.0;
  double weight_point = 0.7;
  double weight_random = 0.3;  // uniform within the limits: often unnatural
  double weight_grasp = 1.5;
  double weight_pca = 0.7;
  // Jitter of archetype angles, degrees.
  double jitter_deg = 6.0;
  // Standard deviation of pose PCA coefficients ("pca" kind), radians, and how many
  // leading components are drawn.
  double pca_sigma = 0.6;
  int pca_components = 12;
  // Standard deviation of the shape coefficients (clamped to +-2.5 sigma).
  double betas_sigma = 1.0;
  // Add 1..max_objects objects (sphere, box, cylinder) held near or in the hand.
  bool objects = false;
  int max_objects = 2;
  // With objects: the share of frames that get them (the rest show the empty hand), so
  // that one training run sees both; 1 = every frame (no random draw is spent).
  double object_probability = 1.0;
  // The hand centre is drawn uniformly in a ball of this radius (m) around the
  // workspace centre (the world origin of the presets).
  Eigen::Vector3d workspace_center = Eigen::Vector3d::Zero();
  double workspace_radius = 0.06;
  // Placement attempts; the one where the most cameras see all 21 keypoints wins.
  int placement_tries = 12;
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

std::vector<std::string> SynthPoseKindNames();  // open fist pinch point random grasp pca

struct SynthObject {
  std::string kind;          // "sphere", "box" or "cylinder"
  Eigen::Vector3d size;      // sphere: (r, r, r); box: edges; cylinder: (r, r, height)
  Rigid3 world_from_object;  // object centre and axes
  Eigen::Vector3f color;     // albedo
  int texture_kind = 0;      // 0 plain, 1 stripes, 2 checker
  RenderMesh mesh;           // in world coordinates
};

struct SynthScene {
  HandSide side = HandSide::kRight;
  std::string pose_kind;
  HandParams params;       // world frame = the rig's world frame
  HandMesh hand;           // posed (world)
  RenderMesh hand_render;  // hand mesh with skin colours and normals
  Eigen::Vector3f skin = Eigen::Vector3f::Ones();
  ShadingOptions lighting;
  std::vector<SynthObject> objects;
  // Drawn besides the hand and the objects (the realistic look's forearm and table,
  // capture/synth_appearance.h): occludes like an object, in no mask. Empty otherwise.
  std::vector<RenderMesh> scenery;
  int cameras_seeing_hand = 0;  // cameras with all 21 keypoints inside the image
};

// The mesh of an object in its own frame (as SampleSynthScene tessellates it): kind
// "sphere" (radius size.x), "box" (edges size), "cylinder" (radius size.x, height
// size.z, along z). Throws InputError for unknown kinds or non-positive sizes.
RenderMesh MakeObjectMesh(const std::string& kind, const Eigen::Vector3d& size);

// Samples one scene. Deterministic in `rng`'s state.
SynthScene SampleSynthScene(const HandModel& model, const HandAnatomy& anatomy,
                            const HandLimits& limits, const Rig& rig,
                            const SynthSceneOptions& options, std::mt19937_64& rng);

// The draws SampleSynthScene is made of, for scenes composed otherwise (the motion of
// capture/synth_sequence.h). Each is deterministic in `rng`'s state.

// A pose of one of SynthPoseKindNames()' kinds, within the limits. Throws InputError
// for another kind.
HandPoseVector SampleSynthPose(const HandModel& model, const HandAnatomy& anatomy,
                               const HandLimits& limits, const SynthSceneOptions& options,
                               const std::string& kind, std::mt19937_64& rng);
// Shape coefficients ~ N(0, betas_sigma^2), clamped to +-2.5 sigma.
Eigen::VectorXd SampleSynthBetas(const HandModel& model, const SynthSceneOptions& options,
                                 std::mt19937_64& rng);
// Where an object held by the posed hand sits: `anchor` on the palm side (or between
// the thumb and index tips for "pinch"), `away` the unit direction it extends to.
void HeldObjectAnchor(const HandParams& params, const Points3d& keypoints,
                      const std::string& pose_kind, Eigen::Vector3d* anchor,
                      Eigen::Vector3d* away);
// A random object (kind, size, rotation, colour, texture) just off the skin at `anchor`
// along `away`; its mesh in the frame of `anchor`.
SynthObject SampleSynthObject(const Eigen::Vector3d& anchor, const Eigen::Vector3d& away,
                              std::mt19937_64& rng);
// Skin tone, per-vertex shade and lighting; scene->hand_render from scene->hand. The
// number of draws does not depend on the pose, so one stream gives every pose the same
// look.
void SampleSynthAppearance(const HandModel& model, std::mt19937_64& rng,
                           SynthScene* scene);
// Cameras whose image holds all `points` (world) with a 2-pixel margin.
int CamerasSeeingAll(const Rig& rig, const Points3d& points);
// A rotation uniform over SO(3).
Eigen::Quaterniond UniformRandomRotation(std::mt19937_64& rng);
// A point uniform in the ball of `radius` around the origin.
Eigen::Vector3d RandomPointInBall(std::mt19937_64& rng, double radius);

}  // namespace handlabel
