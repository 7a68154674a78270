#include "capture/rig_presets.h"

#include <cmath>
#include <random>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// A camera on a sphere around the origin, looking at `target`.
struct Placement {
  double azimuth_deg, elevation_deg, distance;
  Eigen::Vector3d target;
};

Eigen::Vector3d PositionOf(const Placement& p) {
  const double az = p.azimuth_deg * kDeg, el = p.elevation_deg * kDeg;
  return p.distance * Eigen::Vector3d(std::cos(el) * std::cos(az),
                                      std::cos(el) * std::sin(az), std::sin(el));
}

Rigid3 CamFromWorld(const Placement& p) {
  const Eigen::Vector3d eye = PositionOf(p);
  // Up in the image is world +z, except for cameras looking straight down.
  const Eigen::Vector3d dir = (p.target - eye).normalized();
  const Eigen::Vector3d up =
      std::abs(dir.z()) > 0.99 ? Eigen::Vector3d(1, 0, 0) : Eigen::Vector3d(0, 0, 1);
  return LookAt(eye, p.target, up);
}

std::string CameraName(size_t i) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "cam%02zu", i);
  return buf;
}

// A preset: native size, per-camera (fx, fy, cx, cy) and placements; with
// `distortion` (k1, k2, p1, p2 per camera) OPENCV cameras, else PINHOLE.
struct Preset {
  int width, height;
  std::vector<std::array<double, 4>> intrinsics;
  std::vector<Placement> placements;
  std::vector<std::array<double, 4>> distortion;
};

Preset DexYcb() {
  Preset p{640, 480, {}, {}};
  // Eight cameras around a table, at two heights, all aimed near the workspace.
  const double az[8] = {0, 45, 95, 140, 180, 228, 270, 318};
  const double el[8] = {35, 55, 30, 60, 40, 25, 55, 35};
  const double dist[8] = {0.85, 0.95, 0.8, 1.0, 0.9, 0.78, 0.92, 0.82};
  const double fx[8] = {616.1, 614.3, 617.8, 612.9, 615.5, 618.2, 613.7, 616.9};
  for (int i = 0; i < 8; ++i) {
    p.intrinsics.push_back({fx[i], fx[i] - 0.4 + 0.1 * i, 320.0 + (i % 3) - 1.0,
                            240.0 + (i % 2 ? 2.5 : -1.5)});
    p.placements.push_back(
        {az[i], el[i], dist[i], Eigen::Vector3d(0.01 * (i % 3) - 0.01, 0.0, 0.0)});
  }
  return p;
}

Preset OakInk() {
  Preset p{848, 480, {}, {}};
  const double az[4] = {10, 100, 190, 280};
  const double el[4] = {40, 30, 45, 35};
  const double dist[4] = {0.55, 0.6, 0.52, 0.63};
  const double fx[4] = {608.2, 611.5, 606.9, 610.4};
  for (int i = 0; i < 4; ++i) {
    p.intrinsics.push_back({fx[i], fx[i] + 0.3, 424.0 + i - 1.5, 240.0 + 0.7 * i});
    p.placements.push_back({az[i], el[i], dist[i], Eigen::Vector3d::Zero()});
  }
  return p;
}

Preset Ho3d() {
  Preset p{640, 480, {}, {}};
  const double az[5] = {0, 70, 150, 215, 290};
  const double el[5] = {20, 45, 30, 50, 25};
  const double dist[5] = {0.55, 0.7, 0.6, 0.75, 0.5};
  const double fx[5] = {614.6, 613.2, 615.9, 612.7, 616.3};
  for (int i = 0; i < 5; ++i) {
    p.intrinsics.push_back({fx[i], fx[i] + 0.2, 320.0 + 0.5 * i - 1.0, 240.0 - 0.4 * i});
    p.placements.push_back({az[i], el[i], dist[i], Eigen::Vector3d::Zero()});
  }
  return p;
}

// A full-body studio (Panoptic-style dome, mocap stage): five HD cameras around a
// standing person, 2.6-4 m from the hand, aimed at the body rather than at the hand
// (the hand lands off the image centre), wide lenses with barrel distortion. An
// open hand (~19 cm) spans 65-105 px, a grasping one 30-60 px, as in the full-body
// captures where whole-image palm detection misses hands (docs/detector.md).
Preset Studio() {
  Preset p{1920, 1080, {}, {}, {}};
  const double az[5] = {0, 75, 140, 215, 290};
  const double el[5] = {12, 25, 8, 30, 18};
  const double dist[5] = {2.6, 3.2, 4.0, 3.6, 2.9};
  const double fx[5] = {1395.0, 1442.5, 1468.3, 1410.8, 1428.1};
  // Where each camera aims, relative to the hand: the body's centre seen from there.
  const Eigen::Vector3d target[5] = {{0.15, 0.45, 0.4},
                                     {-0.4, 0.1, 0.5},
                                     {0.45, -0.3, 0.15},
                                     {0.2, 0.5, 0.6},
                                     {-0.45, -0.35, 0.3}};
  const double k1[5] = {-0.21, -0.17, -0.24, -0.12, -0.19};
  const double k2[5] = {0.06, 0.04, 0.08, 0.02, 0.05};
  for (int i = 0; i < 5; ++i) {
    p.intrinsics.push_back({fx[i], fx[i] + 0.6, 959.5 + 4.0 * (i - 2), 539.5 - 3.0 * i});
    p.placements.push_back({az[i], el[i], dist[i], target[i]});
    p.distortion.push_back({k1[i], k2[i], 0.0004 * (i - 2), -0.0003 * (i % 2)});
  }
  return p;
}

Camera ScaledCamera(const Preset& p, size_t i, int w, int h) {
  const std::array<double, 4>& k = p.intrinsics[i];
  const double sx = static_cast<double>(w) / p.width;
  const double sy = static_cast<double>(h) / p.height;
  // Pixel centres at integers: x' + 0.5 = s (x + 0.5).
  const double fx = k[0] * sx, fy = k[1] * sy;
  const double cx = (k[2] + 0.5) * sx - 0.5, cy = (k[3] + 0.5) * sy - 0.5;
  if (p.distortion.empty()) return Camera::Pinhole(fx, fy, cx, cy, w, h);
  // Distortion acts on normalised coordinates, so scaling keeps it.
  const std::array<double, 4>& d = p.distortion[i];
  return Camera(CameraModelId::kOpenCV, w, h, {fx, fy, cx, cy, d[0], d[1], d[2], d[3]},
                "rig preset");
}

Rig RandomRig(const RigPresetOptions& o, uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x5eedc0ffee123457ULL);
  const int w = o.width > 0 ? o.width : 640;
  const int h = o.height > 0 ? o.height : 480;
  Rig rig;
  const double start = Uniform(rng, 0, 360);
  for (int i = 0; i < o.num_cameras; ++i) {
    Placement p;
    // Spread over the span with jitter so cameras do not bunch up.
    const double slot = o.azimuth_span_deg / o.num_cameras;
    p.azimuth_deg = start + slot * (i + Uniform(rng, 0.2, 0.8));
    p.elevation_deg = Uniform(rng, o.min_elevation_deg, o.max_elevation_deg);
    p.distance = Uniform(rng, o.min_distance, o.max_distance);
    p.target = Eigen::Vector3d(Uniform(rng, -0.03, 0.03), Uniform(rng, -0.03, 0.03),
                               Uniform(rng, -0.02, 0.02));
    const double fov = Uniform(rng, o.min_fov_deg, o.max_fov_deg) * kDeg;
    const double fx = 0.5 * w / std::tan(0.5 * fov);
    const double fy = fx * Uniform(rng, 0.995, 1.005);
    const double cx = 0.5 * w - 0.5 + Uniform(rng, -0.02, 0.02) * w;
    const double cy = 0.5 * h - 0.5 + Uniform(rng, -0.02, 0.02) * h;
    Camera camera;
    if (o.distortion) {
      camera = Camera(CameraModelId::kOpenCV, w, h,
                      {fx, fy, cx, cy, Uniform(rng, -0.3, 0.1), Uniform(rng, -0.05, 0.1),
                       Uniform(rng, -0.002, 0.002), Uniform(rng, -0.002, 0.002)},
                      "random rig");
    } else {
      camera = Camera::Pinhole(fx, fy, cx, cy, w, h);
    }
    rig.Add({CameraName(i), camera, CamFromWorld(p)});
  }
  return rig;
}

}  // namespace

void RigPresetOptions::Check(const std::string& source) const {
  bool known = false;
  for (const std::string& n : RigPresetNames()) known |= n == preset;
  if (!known) {
    throw InputError(source, "preset", "one of dexycb, oakink, ho3d, studio, random",
                     preset);
  }
  if (width < 0 || height < 0 || (width == 0) != (height == 0) || width > 16384 ||
      height > 16384) {
    throw InputError(source, "size", "both 0 (preset size) or both in 1..16384",
                     std::to_string(width) + "x" + std::to_string(height));
  }
  RequireInRange(source, "num_cameras", num_cameras, 1, 256);
  if (!(min_distance > 0.05 && max_distance >= min_distance)) {
    throw InputError(source, "min_distance/max_distance", "0.05 < min <= max");
  }
  if (!(min_elevation_deg >= -90 && max_elevation_deg <= 90 &&
        min_elevation_deg <= max_elevation_deg)) {
    throw InputError(source, "min/max_elevation_deg", "-90 <= min <= max <= 90");
  }
  if (!(azimuth_span_deg > 0 && azimuth_span_deg <= 360)) {
    throw InputError(source, "azimuth_span_deg", "in (0, 360]");
  }
  if (!(min_fov_deg >= 10 && max_fov_deg <= 150 && min_fov_deg <= max_fov_deg)) {
    throw InputError(source, "min/max_fov_deg", "10 <= min <= max <= 150");
  }
}

std::vector<std::string> RigPresetNames() {
  return {"dexycb", "oakink", "ho3d", "studio", "random"};
}

Rig MakePresetRig(const RigPresetOptions& options, uint64_t seed) {
  options.Check("rig options");
  if (options.preset == "random") return RandomRig(options, seed);
  const Preset p = options.preset == "dexycb"   ? DexYcb()
                   : options.preset == "oakink" ? OakInk()
                   : options.preset == "studio" ? Studio()
                                                : Ho3d();
  const int w = options.width > 0 ? options.width : p.width;
  const int h = options.height > 0 ? options.height : p.height;
  Rig rig;
  for (size_t i = 0; i < p.placements.size(); ++i) {
    rig.Add({CameraName(i), ScaledCamera(p, i, w, h), CamFromWorld(p.placements[i])});
  }
  return rig;
}

}  // namespace handlabel
