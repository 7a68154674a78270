#pragma once
// The SNAP/OpenPose 21-keypoint skeleton (keypoint order in hand/hand_model.h: wrist,
// then thumb, index, middle, ring, pinky, four keypoints each from the palm out) and
// the one finger-colour table every picture of keypoints uses.

#include <array>
#include <cstdint>

#include "hand/hand_model.h"

namespace handlabel {

// SNAP parent of each keypoint; -1 for the wrist. The 20 bones are
// (kSnapParents[k], k) for k = 1..20.
inline constexpr std::array<int, kNumHandKeypoints> kSnapParents = {
    -1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9, 10, 11, 0, 13, 14, 15, 0, 17, 18, 19};

// Name of SNAP keypoint k, as `model info`, CSV columns and exports spell it.
inline constexpr std::array<const char*, kNumHandKeypoints> kSnapKeypointNames = {
    "wrist",      "thumb_cmc", "thumb_mcp", "thumb_ip",   "thumb_tip",  "index_mcp",
    "index_pip",  "index_dip", "index_tip", "middle_mcp", "middle_pip", "middle_dip",
    "middle_tip", "ring_mcp",  "ring_pip",  "ring_dip",   "ring_tip",   "pinky_mcp",
    "pinky_pip",  "pinky_dip", "pinky_tip"};

inline constexpr int kNumHandFingers = 5;

// Finger of SNAP keypoint k, 0-based: 0 thumb, 1 index, 2 middle, 3 ring, 4 pinky;
// -1 for the wrist. A bone belongs to the finger of its child keypoint.
constexpr int SnapFinger(int k) { return k == 0 ? -1 : (k - 1) / 4; }

// One RGB colour per finger (thumb, index, middle, ring, pinky).
inline constexpr std::array<std::array<uint8_t, 3>, kNumHandFingers> kFingerColors = {
    {{255, 60, 60}, {255, 200, 0}, {60, 220, 60}, {40, 160, 255}, {200, 80, 255}}};

// Colour of SNAP keypoint k (and of the bone ending at it): its finger's; the wrist,
// where all fingers meet, takes the thumb's.
constexpr std::array<uint8_t, 3> SnapKeypointColor(int k) {
  return kFingerColors[k == 0 ? 0 : SnapFinger(k)];
}

}  // namespace handlabel
