#include "hand/hand_pose_sampler.h"

#include <algorithm>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Archetype angles in degrees, [joint][twist, spread, bend]. Positive spread turns a
// finger towards the thumb side, positive bend is flexion (see hand_anatomy.h).
using Archetype = std::array<std::array<double, 3>, kNumHandJoints>;

// Native chain order: index, middle, pinky, ring, thumb.
void SetChain(Archetype* a, int chain, std::array<double, 3> base,
              std::array<double, 3> mid, std::array<double, 3> end) {
  (*a)[1 + 3 * chain] = base;
  (*a)[2 + 3 * chain] = mid;
  (*a)[3 + 3 * chain] = end;
}

constexpr int kIndex = 0, kMiddle = 1, kPinky = 2, kRing = 3, kThumb = 4;

void CurlFinger(Archetype* a, int chain, double spread) {
  SetChain(a, chain, {0, spread, 80}, {0, 0, 95}, {0, 0, 60});
}
void StraightFinger(Archetype* a, int chain, double spread) {
  SetChain(a, chain, {0, spread, 5}, {0, 0, 5}, {0, 0, 5});
}

Archetype MakeArchetype(HandPoseKind kind) {
  Archetype a{};
  switch (kind) {
    case HandPoseKind::kOpen:
      StraightFinger(&a, kIndex, 8);
      StraightFinger(&a, kMiddle, 0);
      StraightFinger(&a, kRing, -6);
      StraightFinger(&a, kPinky, -12);
      SetChain(&a, kThumb, {0, 10, 0}, {0, 0, 5}, {0, 0, 5});
      break;
    case HandPoseKind::kFist:
      CurlFinger(&a, kIndex, 2);
      CurlFinger(&a, kMiddle, 0);
      CurlFinger(&a, kRing, -2);
      CurlFinger(&a, kPinky, -4);
      SetChain(&a, kThumb, {10, 15, 35}, {0, 0, 45}, {0, 0, 45});
      break;
    case HandPoseKind::kPoint:
      StraightFinger(&a, kIndex, 3);
      CurlFinger(&a, kMiddle, 0);
      CurlFinger(&a, kRing, -2);
      CurlFinger(&a, kPinky, -4);
      SetChain(&a, kThumb, {10, 15, 35}, {0, 0, 45}, {0, 0, 45});
      break;
    case HandPoseKind::kPinch:
      // Thumb and index flexed towards each other; the other fingers half curled.
      SetChain(&a, kIndex, {0, 5, 40}, {0, 0, 45}, {0, 0, 25});
      SetChain(&a, kMiddle, {0, 0, 30}, {0, 0, 35}, {0, 0, 20});
      SetChain(&a, kRing, {0, -5, 40}, {0, 0, 45}, {0, 0, 25});
      SetChain(&a, kPinky, {0, -10, 50}, {0, 0, 50}, {0, 0, 30});
      SetChain(&a, kThumb, {20, 35, 30}, {0, 5, 20}, {0, 0, 25});
      break;
    case HandPoseKind::kRandom:
      break;
  }
  return a;
}

}  // namespace

std::string HandPoseKindName(HandPoseKind kind) {
  switch (kind) {
    case HandPoseKind::kOpen:
      return "open";
    case HandPoseKind::kFist:
      return "fist";
    case HandPoseKind::kPinch:
      return "pinch";
    case HandPoseKind::kPoint:
      return "point";
    case HandPoseKind::kRandom:
      return "random";
  }
  return "unknown";
}

void HandPoseSamplerOptions::Check(const std::string& source) const {
  const double weights[5] = {weight_open, weight_fist, weight_pinch, weight_point,
                             weight_random};
  const char* const names[5] = {"weight_open", "weight_fist", "weight_pinch",
                                "weight_point", "weight_random"};
  double total = 0;
  for (int i = 0; i < 5; ++i) {
    RequireAtLeast(source, names[i], weights[i], 0);
    total += weights[i];
  }
  if (!(total > 0.0)) {
    throw InputError(source, "weight_*", "at least one weight > 0", "all zero");
  }
  RequireAtLeast(source, "jitter_deg", jitter_deg, 0);
}

SampledHandPose SampleHandPoseOfKind(const HandAnatomy& anatomy, const HandLimits& limits,
                                     HandPoseKind kind, double jitter_deg,
                                     std::mt19937_64& rng) {
  limits.Check("hand pose sampler limits");
  const Archetype archetype = MakeArchetype(kind);
  std::normal_distribution<double> jitter(0.0, 1.0);
  SampledHandPose out;
  out.kind = kind;
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int a = 0; a < 3; ++a) {
      const AngleLimit& limit = limits.joints[j][a];
      double deg;
      if (kind == HandPoseKind::kRandom) {
        deg = std::uniform_real_distribution<double>(limit.min_deg, limit.max_deg)(rng);
      } else {
        deg = archetype[j][a] + jitter_deg * jitter(rng);
      }
      out.angles[3 * (j - 1) + a] = std::clamp(deg, limit.min_deg, limit.max_deg) * kDeg;
    }
  }
  out.hand_pose = HandPoseFromAnatomicalAngles(anatomy, out.angles);
  return out;
}

SampledHandPose SampleHandPose(const HandAnatomy& anatomy, const HandLimits& limits,
                               const HandPoseSamplerOptions& options,
                               std::mt19937_64& rng) {
  options.Check("HandPoseSamplerOptions");
  std::discrete_distribution<int> pick({options.weight_open, options.weight_fist,
                                        options.weight_pinch, options.weight_point,
                                        options.weight_random});
  constexpr HandPoseKind kKinds[5] = {HandPoseKind::kOpen, HandPoseKind::kFist,
                                      HandPoseKind::kPinch, HandPoseKind::kPoint,
                                      HandPoseKind::kRandom};
  return SampleHandPoseOfKind(anatomy, limits, kKinds[pick(rng)], options.jitter_deg,
                              rng);
}

}  // namespace handlabel
