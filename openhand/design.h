#pragma once
// Parametric design of the project's open hand (right hand, MANO axes): bone lengths,
// joint positions, finger radii and palm shape, from published adult anthropometry.
// The builder (open_hand_builder.h) turns a design into a mesh and a HandModel.
//
// Axes (MANO's): fingers point along -x, the back of the hand is +y (palm normal -y),
// the thumb is on +z. Joints are in MANO's native order (0 wrist, 1-3 index, 4-6
// middle, 7-9 pinky, 10-12 ring, 13-15 thumb). Units metres.
//
// Sources of the default numbers (means of adult men and women):
// - Phalanx lengths: Buryanov & Kotiuk, "Proportions of hand segments", Int. J.
//   Morphol. 28(3), 2010 (index 39.8/22.4/15.8 mm, middle 44.6/26.3/17.4, ring
//   41.4/25.7/17.3, little 32.7/18.1/15.7; thumb proximal 32.1, distal 21.7).
// - Hand length 18.0-19.5 cm, hand breadth at the metacarpals 8-9 cm, finger breadths
//   at the PIP 16-21 mm: ANSUR II (2012) and Greiner (1991) summary tables.
// Distal lengths below run from the DIP joint centre to the fingertip surface, so they
// add ~5 mm of pulp to the bone length.

#include <Eigen/Core>
#include <array>
#include <random>
#include <vector>

#include "hand/hand_model.h"

namespace handlabel {

// A long finger (index, middle, ring, pinky).
struct OpenHandFingerDesign {
  Eigen::Vector3d mcp = Eigen::Vector3d::Zero();  // MCP joint relative to the wrist joint
  double spread_deg = 0.0;  // rotation of the finger from -x towards +z (the thumb)
  double droop_deg = 0.0;   // rotation of the finger from -x towards -y (the palm)
  std::array<double, 3> lengths{};  // MCP->PIP, PIP->DIP, DIP->tip surface
  std::array<double, 4> radii{};    // half breadth at MCP, PIP, DIP, tip
};

struct OpenHandThumbDesign {
  Eigen::Vector3d cmc = Eigen::Vector3d::Zero();  // CMC joint relative to the wrist joint
  // Directions of the metacarpal, proximal and distal bones (normalised when used).
  std::array<Eigen::Vector3d, 3> directions;
  std::array<double, 3> lengths{};  // CMC->MCP, MCP->IP, IP->tip surface
  std::array<double, 4> radii{};    // half breadth at CMC (thenar), MCP, IP, tip
};

struct OpenHandDesign {
  // Wrist joint in model coordinates (MANO also keeps its origin near the palm centre).
  Eigen::Vector3d wrist = Eigen::Vector3d(0.09, 0.0, 0.0);
  // index, middle, ring, pinky (anatomical order, not MANO's chain order).
  std::array<OpenHandFingerDesign, 4> fingers;
  OpenHandThumbDesign thumb;
  double finger_thickness = 0.88;   // dorsal-palmar size / lateral size of fingers
  double palm_thickness = 0.032;    // full dorsal-palmar thickness of the palm
  double palm_edge_margin = 0.004;  // palm reaches this far beyond the outer knuckles
  double wrist_half_width = 0.028;  // forearm stub at the wrist
  double wrist_half_thickness = 0.018;
  double wrist_stub_length = 0.030;  // forearm stub beyond the wrist joint (+x) ...
  double wrist_cut = 0.016;          // ... cut flat this far beyond the wrist joint
  // Smooth-union radii: palm parts, palm with fingers, palm with thumb.
  double palm_blend = 0.010;
  double finger_blend = 0.006;
  double thumb_blend = 0.012;

  // Throws InputError (source "open hand design") on non-positive sizes.
  void Check(const std::string& source) const;
};

// Default adult right hand, wrist to middle fingertip ~18.6 cm.
OpenHandDesign DefaultOpenHandDesign();

// Finger index (0 index .. 3 pinky) -> MANO chain start joint (1, 4, 10, 7).
constexpr std::array<int, 4> kFingerFirstJoint = {1, 4, 10, 7};
// HandModel::tip_vertex_ids order is thumb, index, middle, ring, pinky: finger f's tip
// is tip f + 1, the thumb's tip 0.

struct OpenHandSkeleton {
  std::array<Eigen::Vector3d, kNumHandJoints> joints;  // native order
  std::array<Eigen::Vector3d, 5> tips;         // fingertip surface points, thumb first
  std::array<double, kNumHandJoints> radii{};  // body radius at each joint
  std::array<double, 5> tip_radii{};
};
OpenHandSkeleton SkeletonFromDesign(const OpenHandDesign& design);

// ---------------------------------------------------------------------------------
// Implicit surface: tapered capsules with elliptic cross-sections and a rounded palm
// slab, combined with smooth unions. Negative inside; approximately a distance.

struct OpenHandCapsule {
  Eigen::Vector3d a, b;                               // segment end points
  double ra = 0.0, rb = 0.0;                          // lateral radius at a and b
  double thickness = 1.0;                             // dorsal radius / lateral radius
  Eigen::Vector3d dorsal = Eigen::Vector3d::UnitY();  // direction of `thickness`
  int bone = 0;  // native joint that moves this part (skinning region)
};

struct OpenHandShape {
  Eigen::Vector3d wrist;
  // Palm slab: a box rounded by `palm_round`, from x = palm_x0 (wrist side) to palm_x1,
  // half width growing from palm_hw0 to palm_hw1, centred at palm_z, y in
  // [palm_y - palm_hy, palm_y + palm_hy].
  double palm_x0 = 0, palm_x1 = 0, palm_hw0 = 0, palm_hw1 = 0, palm_z = 0, palm_y = 0,
         palm_hy = 0;
  std::vector<OpenHandCapsule> palm;  // wrist stub, knuckle capsules (bone 0)
  std::vector<OpenHandCapsule> thumb;
  std::array<std::vector<OpenHandCapsule>, 4> fingers;
  double palm_blend = 0, finger_blend = 0, thumb_blend = 0;
  double cut_x = 1e9;  // flat wrist end: everything at x > cut_x is removed (rounded)

  // Signed value at p; `bone` (optional) gets the bone of the nearest part.
  double Evaluate(const Eigen::Vector3d& p, int* bone = nullptr) const;
  // Central-difference gradient.
  Eigen::Vector3d Gradient(const Eigen::Vector3d& p, double h = 1e-5) const;
  // Axis-aligned box containing the surface, with a margin.
  void Bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const;
};
OpenHandShape ShapeFromDesign(const OpenHandDesign& design);

// ---------------------------------------------------------------------------------
// Variation for the shape space: relative standard deviations of the design factors.

struct OpenHandVariation {
  double scale = 0.050;          // overall size (hand length SD ~ 5 %)
  double palm_width = 0.040;     // knuckle spacing and palm breadth
  double palm_length = 0.030;    // wrist to knuckles
  double thickness = 0.070;      // palm thickness and finger girth together
  double finger_girth = 0.050;   // finger radii only
  double finger_length = 0.035;  // all long fingers together
  double each_finger = 0.020;    // each finger on its own
  double thumb_length = 0.040;
  double thumb_abduction_deg = 6.0;  // thumb swung away from / towards the index
  void Check(const std::string& source) const;
};

// One random design around `mean`: each factor is a Gaussian with the SD above.
OpenHandDesign SampleOpenHandDesign(const OpenHandDesign& mean,
                                    const OpenHandVariation& variation,
                                    std::mt19937_64& rng);

}  // namespace handlabel
