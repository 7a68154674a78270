#pragma once
// Differences between two rigs with the same camera names, e.g. a calibration and the
// ground truth: focal length (relative), principal point (px), rotation (deg) and
// camera centre (m). Both rigs are first re-expressed with the world at the same
// reference camera, so rigs calibrated in different world frames compare fairly.

#include <string>
#include <vector>

#include "geometry/rig.h"

namespace handlabel {

struct CameraDifference {
  std::string name;
  double focal_rel = 0;     // max over fx, fy of |f_a / f_b - 1|
  double principal_px = 0;  // max over x, y of |c_a - c_b|
  double rotation_deg = 0;
  double centre_m = 0;
};

struct RigDifference {
  std::string reference;  // the camera that defines the common world frame
  std::vector<CameraDifference> cameras;  // in b's order
  CameraDifference worst;                 // per-column maxima, name "max"
};

// Throws InputError naming a camera of b that a lacks, or an unknown reference, with
// the rig (`a_name`, `b_name`: e.g. their files) it is missing from.
// `reference` "" = b's first camera.
RigDifference CompareRigs(const Rig& a, const Rig& b, const std::string& reference = "",
                          const std::string& a_name = "the first rig",
                          const std::string& b_name = "the second rig");

std::string RigDifferenceTable(const RigDifference& difference);

}  // namespace handlabel
