#pragma once
// Synthetic sequences: frames that are moments of one continuous hand motion, for
// measuring jitter and tracking against exact ground truth (docs/synth.md).
//
// The motion repeats a grasp cycle, each cycle with its own random draws:
//   reach    the hand moves from where it last let go to the next pick-up place,
//            fingers going from the last open pose to this cycle's open pose
//   grasp    the fingers close to this cycle's grasp (a partial fist) or pinch
//   carry    the hand moves, with the held object, to the place where it lets go
//   release  the fingers open again; the object stays where it was put down
// Each phase goes from one keyframe to the next along the minimum-jerk profile
// s(u) = 10u^3 - 15u^4 + 6u^5 (Flash and Hogan 1985, how human point-to-point movements
// go): wrist position and finger angles (anatomical, hand_anatomy.h) interpolated
// linearly in s, the root rotation by slerp in s. Velocity and acceleration are zero at
// every keyframe, so the motion is C2 across phases and cycles.
//
// Time is physical: frame f shows time f / fps, and the phases last fixed seconds, so
// frame 2k at 60 fps is frame k at 30 fps. Cycle c's draws come from (seed, c) alone,
// and the shape, skin and lighting from (seed) alone: any frame can be made on its own
// (random access, threads), and the same seed gives the same sequence.
//
// Objects: a cycle with an object picks it up where it lies in front of the palm (or
// between thumb and index tips for a pinch), carries it rigidly with the hand and puts
// it down; the object the previous cycle put down stays there (when max_objects >= 2).

#include <Eigen/Core>
#include <string>

#include "capture/synth_scene.h"
#include "geometry/rig.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_model.h"

namespace handlabel {

struct SynthSequenceOptions {
  bool enabled = false;  // frames form one motion (else every frame is drawn alone)
  double fps = 30.0;     // frames per second: frame f shows time f / fps (> 0)
  // Seconds of each phase of a grasp cycle (> 0): the speeds of the motion.
  double reach_seconds = 1.0;
  double grasp_seconds = 0.5;
  double carry_seconds = 1.0;
  double release_seconds = 0.5;
  // Pick-up and put-down places of the hand centre: uniform in a ball of this radius
  // (m) around the scene's workspace centre. 0.1 m takes reaches of up to 20 cm, about
  // 0.2-0.4 m/s at their fastest with the default phase lengths.
  double motion_radius = 0.1;
  // Keyframe orientations lie within this angle (degrees) of the sequence's own base
  // orientation, so that no phase turns the wrist by more than twice it.
  double rotation_range_deg = 45.0;
  double CycleSeconds() const {
    return reach_seconds + grasp_seconds + carry_seconds + release_seconds;
  }
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

// The minimum-jerk profile on [0, 1] (clamped outside): 0 -> 0, 1 -> 1, first and
// second derivatives zero at both ends.
double MinimumJerk(double u);

// The phase at `seconds` into the sequence: "reach", "grasp", "carry" or "release".
std::string SynthSequencePhase(const SynthSequenceOptions& options, double seconds);

// The scene `seconds` into the sequence of `seed`. The scene's pose_kind is the phase.
// Deterministic in (seed, seconds) and the options; thread-safe.
SynthScene SampleSynthSequenceScene(const HandModel& model, const HandAnatomy& anatomy,
                                    const HandLimits& limits, const Rig& rig,
                                    const SynthSceneOptions& scene_options,
                                    const SynthSequenceOptions& options, uint64_t seed,
                                    double seconds);

}  // namespace handlabel
