#include "capture/synth_sequence.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "image/mesh_primitives.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// The sequence's random streams, apart from the per-frame streams of
// capture/synth_capture.cc (1-4, 2 + 16 c and 3 + 16 c).
constexpr uint64_t kSequenceStream = 5;  // (seed, 0): shape, base orientation, look
constexpr uint64_t kCycleStream = 6;     // (seed, c + 1): what grasp cycle c draws

const char* const kPhaseNames[4] = {"reach", "grasp", "carry", "release"};

// Everything a sequence's draws need.
struct SequenceContext {
  const HandModel& model;
  const HandAnatomy& anatomy;
  const HandLimits& limits;
  const Rig& rig;
  const SynthSceneOptions& scene;
  const SynthSequenceOptions& options;
  uint64_t seed;
};

// What every frame of a sequence shares: one person, one base orientation.
struct SequenceShared {
  Eigen::VectorXd betas;
  Eigen::Quaterniond base_rotation;
  Eigen::Vector3d wrist;  // rest wrist joint of the shaped hand: the root's pivot
};

// The hand at a keyframe (or between two).
struct HandKeyframe {
  Eigen::Quaterniond rotation;  // root rotation about the rest wrist
  Eigen::Vector3d transl;       // the model's translation
  HandPoseVector angles;        // anatomical finger angles (radians)
};

// What grasp cycle c draws. The object is in the frame of the hand without root
// rotation or translation, so the hand's rigid motion carries it.
struct GraspCycle {
  std::string grasp_kind;  // "grasp" or "pinch"
  HandPoseVector open_angles, grasp_angles;
  Eigen::Quaterniond pick_rotation, place_rotation;
  Eigen::Vector3d pick_transl, place_transl;
  std::optional<SynthObject> object;
};

// The place in time: which cycle, which phase (0..3 = kPhaseNames) and the minimum-jerk
// progress through it.
struct SequenceMoment {
  int64_t cycle = 0;
  int phase = 0;
  double progress = 0;
};

SequenceMoment MomentAt(const SynthSequenceOptions& o, double seconds) {
  HL_CHECK(seconds >= 0 && std::isfinite(seconds), "time >= 0 into the sequence");
  const std::array<double, 4> durations = {o.reach_seconds, o.grasp_seconds,
                                           o.carry_seconds, o.release_seconds};
  SequenceMoment m;
  const double cycle = std::floor(seconds / o.CycleSeconds());
  m.cycle = static_cast<int64_t>(cycle);
  double u = seconds - cycle * o.CycleSeconds();
  while (m.phase < 3 && u >= durations[m.phase]) u -= durations[m.phase++];
  m.progress = MinimumJerk(u / durations[m.phase]);
  return m;
}

HandPoseVector AnglesOf(const HandAnatomy& anatomy, const HandPoseVector& hand_pose) {
  HandPoseVector angles;
  HandAnatomicalAngles(anatomy, hand_pose.data(), angles.data());
  return angles;
}

// The hand's rigid motion: world = R (x - wrist) + wrist + transl for points x of the
// hand without root rotation or translation.
Rigid3 WorldFromRestHand(const Eigen::Quaterniond& rotation,
                         const Eigen::Vector3d& transl, const Eigen::Vector3d& wrist) {
  return Rigid3(rotation, wrist + transl - rotation * wrist);
}

SequenceShared DrawShared(const SequenceContext& ctx) {
  std::mt19937_64 rng(MixSeed(ctx.seed, 0, kSequenceStream));
  SequenceShared shared;
  shared.betas = SampleSynthBetas(ctx.model, ctx.scene, rng);
  shared.base_rotation = UniformRandomRotation(rng);
  HandParams rest;
  rest.betas = shared.betas;
  shared.wrist = PoseHand(ctx.model, rest).joints.row(0).transpose();
  return shared;
}

// A keyframe place for the hand posed as `rest_keypoints` (no root rotation or
// translation): an orientation near the base one and a hand centre in the motion ball;
// of placement_tries, the one the most cameras see entirely.
void PlaceKeyframe(const SequenceContext& ctx, const SequenceShared& shared,
                   const Points3d& rest_keypoints, std::mt19937_64& rng,
                   Eigen::Quaterniond* rotation, Eigen::Vector3d* transl) {
  const Eigen::Vector3d centre = rest_keypoints.colwise().mean().transpose();
  int best = -1;
  for (int t = 0; t < ctx.scene.placement_tries; ++t) {
    const Eigen::Vector3d turn =
        RandomPointInBall(rng, ctx.options.rotation_range_deg * kDeg);
    const Eigen::Quaterniond q =
        shared.base_rotation *
        Eigen::Quaterniond(Eigen::AngleAxisd(turn.norm(), turn.normalized()));
    const Eigen::Vector3d target =
        ctx.scene.workspace_center + RandomPointInBall(rng, ctx.options.motion_radius);
    const Rigid3 world_from_rest = WorldFromRestHand(
        q, target - (q * (centre - shared.wrist) + shared.wrist), shared.wrist);
    Points3d keypoints(rest_keypoints.rows(), 3);
    for (Eigen::Index i = 0; i < keypoints.rows(); ++i) {
      keypoints.row(i) =
          (world_from_rest * Eigen::Vector3d(rest_keypoints.row(i))).transpose();
    }
    const int seen = CamerasSeeingAll(ctx.rig, keypoints);
    if (seen > best) {
      best = seen;
      *rotation = q;
      *transl = target - (q * (centre - shared.wrist) + shared.wrist);
    }
    if (best == static_cast<int>(ctx.rig.size())) break;
  }
}

// Cycle -1 is drawn like the others: its put-down place and open hand are where the
// sequence starts.
GraspCycle DrawCycle(const SequenceContext& ctx, const SequenceShared& shared,
                     int64_t cycle) {
  std::mt19937_64 rng(MixSeed(ctx.seed, static_cast<uint64_t>(cycle + 1), kCycleStream));
  const SynthSceneOptions& o = ctx.scene;
  GraspCycle c;
  c.open_angles = AnglesOf(
      ctx.anatomy, SampleSynthPose(ctx.model, ctx.anatomy, ctx.limits, o, "open", rng));
  const double pinch_share = o.weight_pinch / (o.weight_pinch + o.weight_grasp);
  c.grasp_kind = Uniform(rng, 0, 1) < pinch_share ? "pinch" : "grasp";
  HandParams held;
  held.betas = shared.betas;
  held.hand_pose =
      SampleSynthPose(ctx.model, ctx.anatomy, ctx.limits, o, c.grasp_kind, rng);
  c.grasp_angles = AnglesOf(ctx.anatomy, held.hand_pose);
  const HandMesh rest = PoseHand(ctx.model, held);
  PlaceKeyframe(ctx, shared, rest.keypoints, rng, &c.pick_rotation, &c.pick_transl);
  PlaceKeyframe(ctx, shared, rest.keypoints, rng, &c.place_rotation, &c.place_transl);
  const bool with_object = o.objects && (o.object_probability >= 1.0 ||
                                         Uniform(rng, 0, 1) < o.object_probability);
  if (with_object) {
    Eigen::Vector3d anchor, away;
    HeldObjectAnchor(held, rest.keypoints, c.grasp_kind, &anchor, &away);
    c.object = SampleSynthObject(anchor, away, rng);
  }
  return c;
}

HandKeyframe Between(const HandKeyframe& a, const HandKeyframe& b, double s) {
  return {a.rotation.slerp(s, b.rotation), (1 - s) * a.transl + s * b.transl,
          (1 - s) * a.angles + s * b.angles};
}

// The hand at moment `m` of cycle `cur`, which starts where `prev` ended.
HandKeyframe HandAt(const GraspCycle& prev, const GraspCycle& cur,
                    const SequenceMoment& m) {
  const std::array<HandKeyframe, 5> keys = {
      HandKeyframe{prev.place_rotation, prev.place_transl, prev.open_angles},
      HandKeyframe{cur.pick_rotation, cur.pick_transl, cur.open_angles},
      HandKeyframe{cur.pick_rotation, cur.pick_transl, cur.grasp_angles},
      HandKeyframe{cur.place_rotation, cur.place_transl, cur.grasp_angles},
      HandKeyframe{cur.place_rotation, cur.place_transl, cur.open_angles}};
  return Between(keys[m.phase], keys[m.phase + 1], m.progress);
}

// `object` (in the rest hand's frame) moved by the hand's rigid motion.
SynthObject PlacedObject(const SynthObject& object, const Rigid3& world_from_rest) {
  SynthObject placed = object;
  placed.world_from_object = world_from_rest * object.world_from_object;
  TransformMesh(world_from_rest, &placed.mesh);
  return placed;
}

// The held object lies at the pick-up place until grasped, moves with the hand while
// carried and stays where it was put down; the previous cycle's stays where it was put.
void AddSequenceObjects(const SequenceContext& ctx, const SequenceShared& shared,
                        const GraspCycle& prev, const GraspCycle& cur,
                        const SequenceMoment& m, const HandKeyframe& hand,
                        SynthScene* scene) {
  if (cur.object) {
    const bool carried = m.phase == 2;
    const Eigen::Quaterniond& q = carried       ? hand.rotation
                                  : m.phase < 2 ? cur.pick_rotation
                                                : cur.place_rotation;
    const Eigen::Vector3d& t = carried       ? hand.transl
                               : m.phase < 2 ? cur.pick_transl
                                             : cur.place_transl;
    scene->objects.push_back(
        PlacedObject(*cur.object, WorldFromRestHand(q, t, shared.wrist)));
  }
  if (prev.object && ctx.scene.max_objects >= 2) {
    scene->objects.push_back(PlacedObject(
        *prev.object,
        WorldFromRestHand(prev.place_rotation, prev.place_transl, shared.wrist)));
  }
}

}  // namespace

void SynthSequenceOptions::Check(const std::string& source) const {
  RequireInRange(source, "fps", fps, 1e-3, 1e4, "frames per second in (0, 10000]");
  RequireInRange(source, "reach_seconds", reach_seconds, 1e-3, 600);
  RequireInRange(source, "grasp_seconds", grasp_seconds, 1e-3, 600);
  RequireInRange(source, "carry_seconds", carry_seconds, 1e-3, 600);
  RequireInRange(source, "release_seconds", release_seconds, 1e-3, 600);
  RequireInRange(source, "motion_radius", motion_radius, 0, 1, "metres in [0, 1]");
  RequireInRange(source, "rotation_range_deg", rotation_range_deg, 0, 180);
}

double MinimumJerk(double u) {
  const double x = std::clamp(u, 0.0, 1.0);
  return x * x * x * (10 + x * (-15 + 6 * x));
}

std::string SynthSequencePhase(const SynthSequenceOptions& options, double seconds) {
  return kPhaseNames[MomentAt(options, seconds).phase];
}

SynthScene SampleSynthSequenceScene(const HandModel& model, const HandAnatomy& anatomy,
                                    const HandLimits& limits, const Rig& rig,
                                    const SynthSceneOptions& scene_options,
                                    const SynthSequenceOptions& options, uint64_t seed,
                                    double seconds) {
  const SequenceContext ctx{model, anatomy, limits, rig, scene_options, options, seed};
  const SequenceShared shared = DrawShared(ctx);
  const SequenceMoment m = MomentAt(options, seconds);
  const GraspCycle prev = DrawCycle(ctx, shared, m.cycle - 1);
  const GraspCycle cur = DrawCycle(ctx, shared, m.cycle);
  const HandKeyframe hand = HandAt(prev, cur, m);

  SynthScene scene;
  scene.side = model.side;
  scene.pose_kind = kPhaseNames[m.phase];
  const Eigen::AngleAxisd root(hand.rotation);
  scene.params.global_orient = root.angle() * root.axis();
  scene.params.hand_pose = HandPoseFromAnatomicalAngles(anatomy, hand.angles);
  scene.params.betas = shared.betas;
  scene.params.transl = hand.transl;
  scene.hand = PoseHand(model, scene.params);
  scene.cameras_seeing_hand = CamerasSeeingAll(rig, scene.hand.keypoints);
  // One stream for every frame: the same skin and lights throughout.
  std::mt19937_64 look_rng(MixSeed(seed, 1, kSequenceStream));
  SampleSynthAppearance(model, look_rng, &scene);
  AddSequenceObjects(ctx, shared, prev, cur, m, hand, &scene);
  return scene;
}

}  // namespace handlabel
