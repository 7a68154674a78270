#pragma once
// Camera rigs for synthetic captures: presets that mimic the public multi-view hand
// datasets, and random rigs.
//
// World frame of every preset: a table frame with z up and the origin at the centre of
// the workspace where the hand is placed; cameras look at points near the origin.
//
//   preset   cameras  size      focal (px)  distance   model
//   dexycb   8        640x480   ~615        0.75-1.0 m PINHOLE  (RealSense D415 colour)
//   oakink   4        848x480   ~610        0.5-0.65 m PINHOLE  (RealSense D435 colour)
//   ho3d     5        640x480   ~614        0.5-0.75 m PINHOLE  (RealSense D415 colour)
//   studio   5        1920x1080 ~1400-1470  2.6-4.0 m  OPENCV   (full-body studio, small
//                                                               hands, barrel distortion)
//   random   n        size      from FOV    sphere     PINHOLE or OPENCV (distortion)
// Preset rigs are fixed (independent of the seed); random rigs depend only on the seed.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/rig.h"

namespace handlabel {

struct RigPresetOptions {
  // One of RigPresetNames().
  std::string preset = "dexycb";
  // Image size; 0 = the preset's own. Intrinsics are scaled to the requested size
  // (independently in x and y), so the field of view is kept.
  int width = 0;
  int height = 0;
  // Random rigs only: number of cameras (>= 1).
  int num_cameras = 6;
  // Random rigs only: distance range of the cameras from the workspace centre (m).
  double min_distance = 0.5;
  double max_distance = 1.0;
  // Random rigs only: elevation range above the table plane (degrees, -90..90) and the
  // azimuth span the cameras are spread over (degrees, 0..360).
  double min_elevation_deg = 10.0;
  double max_elevation_deg = 70.0;
  double azimuth_span_deg = 360.0;
  // Random rigs only: horizontal field of view range (degrees, 10..150).
  double min_fov_deg = 50.0;
  double max_fov_deg = 75.0;
  // Random rigs only: OPENCV model with random radial/tangential distortion
  // (k1 in [-0.3, 0.1], k2 in [-0.05, 0.1], |p1|, |p2| <= 0.002) instead of PINHOLE.
  bool distortion = false;
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

std::vector<std::string> RigPresetNames();

// The rig, camera names "cam00", "cam01", ... `seed` only matters for random rigs.
Rig MakePresetRig(const RigPresetOptions& options, uint64_t seed);

}  // namespace handlabel
