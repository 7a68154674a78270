#pragma once
// Pictures and tables of a rig for people: `handlabel cameras show`.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/rig.h"

namespace handlabel {

struct RigPlotOptions {
  // Width and height of each of the two panels, pixels.
  int panel_size = 600;
  // Frustum depth in metres; <= 0 picks 20 % of the rig's extent (at least 5 cm).
  double frustum_depth = 0;
  // Optional extra world points drawn as dots (e.g. board corners), metres.
  std::vector<Eigen::Vector3d> points;
  // Title printed above the panels.
  std::string title;
  void Check(const std::string& source) const;
};

// Writes a PNG with two orthographic views of the camera frusta: from above (looking
// down the rig's mean "up" axis, the mean of the cameras' -y axes) and from the side,
// drawn with image/draw.h. Always PNG, whatever the extension; creates missing parent
// folders; throws Error naming the path if the file cannot be written.
void PlotRig(const Rig& rig, const std::string& png_path,
             const RigPlotOptions& options = {});

// A fixed-width table: name, model, size, fx, fy, cx, cy, distortion, centre (world),
// viewing direction, distance to the nearest other camera.
std::string RigTable(const Rig& rig);

}  // namespace handlabel
