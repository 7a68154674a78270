#include "openhand/design.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

OpenHandFingerDesign Finger(Eigen::Vector3d mcp, double spread_deg,
                            std::array<double, 3> lengths_mm,
                            std::array<double, 4> radii_mm) {
  OpenHandFingerDesign f;
  f.mcp = mcp;
  f.spread_deg = spread_deg;
  f.droop_deg = 2.0;
  for (int i = 0; i < 3; ++i) f.lengths[i] = lengths_mm[i] * 1e-3;
  for (int i = 0; i < 4; ++i) f.radii[i] = radii_mm[i] * 1e-3;
  return f;
}

// Direction of bone k (0 proximal) of a long finger: spread about +y towards +z, then a
// droop towards the palm that grows along the finger (a relaxed, slightly curled hand).
Eigen::Vector3d FingerDirection(const OpenHandFingerDesign& f, int k) {
  const double s = f.spread_deg * kDeg;
  const double d = f.droop_deg * (k + 1) * kDeg;
  return Eigen::Vector3d(-std::cos(s) * std::cos(d), -std::sin(d),
                         std::sin(s) * std::cos(d));
}

double SmoothMin(double a, double b, double k) {
  if (k <= 0.0) return std::min(a, b);
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

double CapsuleValue(const OpenHandCapsule& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = c.b - c.a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - c.a).dot(d) / len2, 0.0, 1.0) : 0.0;
  const Eigen::Vector3d q = p - (c.a + t * d);
  Eigen::Vector3d e = c.dorsal;
  if (len2 > 0) e -= e.dot(d) * d / len2;
  e.normalize();
  const double qd = q.dot(e);
  const double rest2 = std::max(q.squaredNorm() - qd * qd, 0.0);
  const double scaled = std::sqrt(rest2 + (qd / c.thickness) * (qd / c.thickness));
  // Scale back so the value is roughly a distance in the thin direction as well.
  return (scaled - (c.ra + t * (c.rb - c.ra))) * std::min(1.0, c.thickness);
}

double PalmSlabValue(const OpenHandShape& s, const Eigen::Vector3d& p) {
  const double u = std::clamp((s.palm_x0 - p.x()) / (s.palm_x0 - s.palm_x1), 0.0, 1.0);
  const double hw = s.palm_hw0 + u * (s.palm_hw1 - s.palm_hw0);
  const Eigen::Vector3d c(0.5 * (s.palm_x0 + s.palm_x1), s.palm_y, s.palm_z);
  const Eigen::Vector3d h(0.5 * (s.palm_x0 - s.palm_x1), s.palm_hy, hw);
  const double round = 0.95 * std::min(s.palm_hy, hw);
  const Eigen::Vector3d q = (p - c).cwiseAbs() - (h - Eigen::Vector3d::Constant(round));
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0) - round;
}

}  // namespace

void OpenHandDesign::Check(const std::string& source) const {
  auto positive = [&](double v, const std::string& field) {
    RequireGreater(source, field, v, 0, "a positive value");
  };
  for (int f = 0; f < 4; ++f) {
    for (double l : fingers[f].lengths) positive(l, "fingers.lengths");
    for (double r : fingers[f].radii) positive(r, "fingers.radii");
  }
  for (double l : thumb.lengths) positive(l, "thumb.lengths");
  for (double r : thumb.radii) positive(r, "thumb.radii");
  for (const auto& d : thumb.directions) positive(d.norm(), "thumb.directions");
  positive(finger_thickness, "finger_thickness");
  positive(palm_thickness, "palm_thickness");
  positive(wrist_half_width, "wrist_half_width");
  positive(wrist_half_thickness, "wrist_half_thickness");
  positive(wrist_stub_length, "wrist_stub_length");
  positive(wrist_cut, "wrist_cut");
}

OpenHandDesign DefaultOpenHandDesign() {
  OpenHandDesign d;
  // MCP joints relative to the wrist joint: the knuckle line arches (middle most distal,
  // little finger ~13 mm proximal) and the transverse arch lowers the outer knuckles.
  d.fingers[0] =
      Finger({-0.089, -0.001, 0.027}, 8.5, {39.8, 22.4, 20.8}, {10.2, 9.4, 8.5, 7.5});
  d.fingers[1] =
      Finger({-0.093, 0.002, 0.006}, 1.0, {44.6, 26.3, 22.4}, {10.4, 9.6, 8.6, 7.6});
  d.fingers[2] =
      Finger({-0.088, 0.000, -0.014}, -5.5, {41.4, 25.7, 22.3}, {9.8, 9.0, 8.1, 7.3});
  d.fingers[3] =
      Finger({-0.080, -0.003, -0.032}, -13.0, {32.7, 18.1, 20.7}, {8.9, 8.2, 7.4, 6.7});
  // Thumb: CMC on the radial, palmar side of the wrist; the rest pose is abducted and
  // slightly pronated, pointing distally and radially as in MANO's template.
  d.thumb.cmc = Eigen::Vector3d(-0.022, -0.012, 0.018);
  d.thumb.directions = {Eigen::Vector3d(-0.55, -0.18, 0.81),
                        Eigen::Vector3d(-0.70, -0.10, 0.71),
                        Eigen::Vector3d(-0.78, -0.05, 0.62)};
  d.thumb.lengths = {0.044, 0.031, 0.0265};
  d.thumb.radii = {0.0140, 0.0115, 0.0108, 0.0092};
  return d;
}

OpenHandSkeleton SkeletonFromDesign(const OpenHandDesign& design) {
  OpenHandSkeleton s;
  s.joints[0] = design.wrist;
  s.radii[0] = design.wrist_half_width;
  for (int f = 0; f < 4; ++f) {
    const OpenHandFingerDesign& fd = design.fingers[f];
    const int j0 = kFingerFirstJoint[f];
    Eigen::Vector3d p = design.wrist + fd.mcp;
    for (int k = 0; k < 3; ++k) {
      s.joints[j0 + k] = p;
      s.radii[j0 + k] = fd.radii[k];
      p += fd.lengths[k] * FingerDirection(fd, k);
    }
    s.tips[f + 1] = p;
    s.tip_radii[f + 1] = fd.radii[3];
  }
  const OpenHandThumbDesign& t = design.thumb;
  Eigen::Vector3d p = design.wrist + t.cmc;
  for (int k = 0; k < 3; ++k) {
    s.joints[13 + k] = p;
    s.radii[13 + k] = t.radii[k];
    p += t.lengths[k] * t.directions[k].normalized();
  }
  s.tips[0] = p;
  s.tip_radii[0] = t.radii[3];
  return s;
}

OpenHandShape ShapeFromDesign(const OpenHandDesign& design) {
  design.Check("open hand design");
  const OpenHandSkeleton sk = SkeletonFromDesign(design);
  OpenHandShape s;
  s.wrist = design.wrist;
  s.palm_blend = design.palm_blend;
  s.finger_blend = design.finger_blend;
  s.thumb_blend = design.thumb_blend;
  s.cut_x = design.wrist.x() + design.wrist_cut;

  // Palm slab from the wrist to just before the knuckles.
  const Eigen::Vector3d& index_mcp = sk.joints[1];
  const Eigen::Vector3d& pinky_mcp = sk.joints[7];
  const double radial = index_mcp.z() + design.fingers[0].radii[0];
  const double ulnar = pinky_mcp.z() - design.fingers[3].radii[0];
  s.palm_x0 = design.wrist.x() - 0.005;
  s.palm_x1 = std::max(index_mcp.x(), pinky_mcp.x()) + 0.006;
  s.palm_z = 0.5 * (radial + ulnar);
  s.palm_hw1 = 0.5 * (radial - ulnar) + design.palm_edge_margin;
  s.palm_hw0 = std::min(design.wrist_half_width, s.palm_hw1);
  s.palm_hy = 0.5 * design.palm_thickness;
  s.palm_y = design.wrist.y() - 0.1 * design.palm_thickness;

  // Forearm stub, closed with a round cap beyond the wrist.
  OpenHandCapsule stub;
  stub.a = design.wrist + Eigen::Vector3d(design.wrist_stub_length, 0, 0);
  stub.b = design.wrist - Eigen::Vector3d(0.012, 0, 0);
  stub.ra = stub.rb = design.wrist_half_width;
  stub.thickness = design.wrist_half_thickness / design.wrist_half_width;
  s.palm.push_back(stub);

  // Knuckles: metacarpal heads as capsules from mid-palm to each MCP joint.
  for (int f = 0; f < 4; ++f) {
    const Eigen::Vector3d& mcp = sk.joints[kFingerFirstJoint[f]];
    OpenHandCapsule k;
    k.b = mcp;
    k.a = Eigen::Vector3d(design.wrist.x() + 0.5 * (mcp.x() - design.wrist.x()), mcp.y(),
                          design.wrist.z() + 0.8 * (mcp.z() - design.wrist.z()));
    k.ra = k.rb = design.fingers[f].radii[0];
    k.thickness = 0.85 * s.palm_hy / k.rb;
    s.palm.push_back(k);
  }

  // Thumb: thenar eminence around the metacarpal, then the phalanges.
  const Eigen::Vector3d thumb_dorsal = Eigen::Vector3d(0.3, 1.0, 1.0).normalized();
  for (int k = 0; k < 3; ++k) {
    OpenHandCapsule c;
    c.a = sk.joints[13 + k];
    c.b = k < 2
              ? sk.joints[14 + k]
              : Eigen::Vector3d(sk.tips[0] - design.thumb.radii[3] *
                                                 design.thumb.directions[2].normalized());
    c.ra = design.thumb.radii[k];
    c.rb = design.thumb.radii[k + 1];
    c.thickness = k == 0 ? 1.0 : design.finger_thickness;
    c.dorsal = thumb_dorsal;
    c.bone = 13 + k;
    s.thumb.push_back(c);
  }

  for (int f = 0; f < 4; ++f) {
    const int j0 = kFingerFirstJoint[f];
    const OpenHandFingerDesign& fd = design.fingers[f];
    for (int k = 0; k < 3; ++k) {
      OpenHandCapsule c;
      c.a = sk.joints[j0 + k];
      c.b = k < 2 ? sk.joints[j0 + k + 1]
                  : Eigen::Vector3d(sk.tips[f + 1] -
                                    fd.radii[3] * (sk.tips[f + 1] - c.a).normalized());
      c.ra = fd.radii[k];
      c.rb = fd.radii[k + 1];
      c.thickness = design.finger_thickness;
      c.bone = j0 + k;
      s.fingers[f].push_back(c);
    }
  }
  return s;
}

double OpenHandShape::Evaluate(const Eigen::Vector3d& p, int* bone) const {
  double best = PalmSlabValue(*this, p);
  int best_bone = 0;
  double palm_value = best;
  for (const OpenHandCapsule& c : palm) {
    const double v = CapsuleValue(c, p);
    palm_value = SmoothMin(palm_value, v, palm_blend);
    if (v < best) best = v, best_bone = c.bone;
  }
  double finger_value = 1e9;
  for (const auto& chain : fingers) {
    for (const OpenHandCapsule& c : chain) {
      const double v = CapsuleValue(c, p);
      finger_value = std::min(finger_value, v);
      if (v < best) best = v, best_bone = c.bone;
    }
  }
  double thumb_value = 1e9;
  for (const OpenHandCapsule& c : thumb) {
    const double v = CapsuleValue(c, p);
    thumb_value = std::min(thumb_value, v);
    if (v < best) best = v, best_bone = c.bone;
  }
  if (bone) *bone = best_bone;
  const double hand = SmoothMin(palm_value, finger_value, finger_blend);
  const double whole = SmoothMin(hand, thumb_value, thumb_blend);
  // Flat wrist end with a rounded rim (smooth intersection with x <= cut_x).
  return -SmoothMin(-whole, -(p.x() - cut_x), palm_blend);
}

Eigen::Vector3d OpenHandShape::Gradient(const Eigen::Vector3d& p, double h) const {
  Eigen::Vector3d g;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d a = p, b = p;
    a[i] += h;
    b[i] -= h;
    g[i] = (Evaluate(a) - Evaluate(b)) / (2 * h);
  }
  return g;
}

void OpenHandShape::Bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const {
  *lo = Eigen::Vector3d::Constant(1e9);
  *hi = Eigen::Vector3d::Constant(-1e9);
  auto grow = [&](const OpenHandCapsule& c) {
    const double r = std::max(c.ra, c.rb) * std::max(1.0, c.thickness);
    for (const Eigen::Vector3d& e : {c.a, c.b}) {
      *lo = lo->cwiseMin(e - Eigen::Vector3d::Constant(r));
      *hi = hi->cwiseMax(e + Eigen::Vector3d::Constant(r));
    }
  };
  for (const auto& c : palm) grow(c);
  for (const auto& c : thumb) grow(c);
  for (const auto& chain : fingers)
    for (const auto& c : chain) grow(c);
  const Eigen::Vector3d slab_lo(palm_x1, palm_y - palm_hy, palm_z - palm_hw1);
  const Eigen::Vector3d slab_hi(palm_x0, palm_y + palm_hy, palm_z + palm_hw1);
  *lo = lo->cwiseMin(slab_lo);
  *hi = hi->cwiseMax(slab_hi);
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(0.01);
  *lo -= margin;
  *hi += margin;
}

void OpenHandVariation::Check(const std::string& source) const {
  for (double v : {scale, palm_width, palm_length, thickness, finger_girth, finger_length,
                   each_finger, thumb_length, thumb_abduction_deg}) {
    RequireInRange(source, "standard deviations", v, 0, 50, "values in [0, 50]");
  }
}

OpenHandDesign SampleOpenHandDesign(const OpenHandDesign& mean,
                                    const OpenHandVariation& v, std::mt19937_64& rng) {
  v.Check("open hand variation");
  std::normal_distribution<double> normal(0.0, 1.0);
  // Factors are drawn in a fixed order so the same seed gives the same designs.
  auto factor = [&](double sd) { return std::max(0.5, 1.0 + sd * normal(rng)); };
  const double scale = factor(v.scale);
  const double width = factor(v.palm_width);
  const double length = factor(v.palm_length);
  const double thick = factor(v.thickness);
  const double girth = factor(v.finger_girth);
  const double finger_length = factor(v.finger_length);
  std::array<double, 4> each;
  for (double& e : each) e = factor(v.each_finger);
  const double thumb_length = factor(v.thumb_length);
  const double abduction = v.thumb_abduction_deg * normal(rng) * kDeg;

  OpenHandDesign d = mean;
  auto place = [&](const Eigen::Vector3d& rel) -> Eigen::Vector3d {
    return Eigen::Vector3d(rel.x() * length, rel.y() * thick, rel.z() * width) * scale;
  };
  for (int f = 0; f < 4; ++f) {
    OpenHandFingerDesign& fd = d.fingers[f];
    fd.mcp = place(fd.mcp);
    for (double& l : fd.lengths) l *= scale * finger_length * each[f];
    for (double& r : fd.radii) r *= scale * girth * std::sqrt(thick);
  }
  OpenHandThumbDesign& t = d.thumb;
  t.cmc = place(t.cmc);
  for (double& l : t.lengths) l *= scale * thumb_length;
  for (double& r : t.radii) r *= scale * girth * std::sqrt(thick);
  const Eigen::Matrix3d swing =
      Eigen::AngleAxisd(abduction, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (auto& dir : t.directions) dir = swing * dir;
  d.palm_thickness *= scale * thick;
  d.wrist_half_width *= scale * width;
  d.wrist_half_thickness *= scale * thick;
  d.wrist_stub_length *= scale;
  d.wrist_cut *= scale;
  d.palm_edge_margin *= scale * width;
  d.palm_blend *= scale;
  d.finger_blend *= scale;
  d.thumb_blend *= scale;
  return d;
}

}  // namespace handlabel
