#pragma once
// Random natural hand poses within anatomical limits, for synthetic data: archetypes
// (open, fist, pinch, point) with jitter, and uniform draws within the limits. Poses
// are generated as anatomical angles (hand_anatomy.h) and converted to the model's
// axis-angle hand_pose, so they work for any MANO-structured model and either side.

#include <random>
#include <string>

#include "hand/hand_anatomy.h"

namespace handlabel {

enum class HandPoseKind { kOpen, kFist, kPinch, kPoint, kRandom };
std::string HandPoseKindName(HandPoseKind kind);

struct HandPoseSamplerOptions {
  // Relative frequencies of the pose kinds (>= 0, not all zero).
  double weight_open = 1.0;
  double weight_fist = 1.0;
  double weight_pinch = 1.0;
  double weight_point = 1.0;
  double weight_random = 1.0;
  // Standard deviation of the Gaussian jitter added to each archetype angle, degrees
  // (the result is clamped to the limits).
  double jitter_deg = 6.0;
  void Check(const std::string& source) const;
};

struct SampledHandPose {
  HandPoseKind kind = HandPoseKind::kOpen;
  HandPoseVector angles = HandPoseVector::Zero();     // anatomical angles, radians
  HandPoseVector hand_pose = HandPoseVector::Zero();  // axis-angle for the model
};

// One pose of the given kind: archetype angles + jitter, clamped to `limits`;
// kRandom draws every angle uniformly within the limits.
SampledHandPose SampleHandPoseOfKind(const HandAnatomy& anatomy, const HandLimits& limits,
                                     HandPoseKind kind, double jitter_deg,
                                     std::mt19937_64& rng);
// Draws the kind by the option weights, then SampleHandPoseOfKind.
SampledHandPose SampleHandPose(const HandAnatomy& anatomy, const HandLimits& limits,
                               const HandPoseSamplerOptions& options,
                               std::mt19937_64& rng);

}  // namespace handlabel
