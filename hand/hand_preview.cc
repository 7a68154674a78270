#include "hand/hand_preview.h"

#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "hand/hand_anatomy.h"

namespace handlabel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Native chain start joints: index 1, middle 4, pinky 7, ring 10, thumb 13.
HandParams FromAngles(const HandAnatomy& anatomy,
                      const std::array<std::array<double, 3>, kNumHandJoints>& deg) {
  HandPoseVector angles = HandPoseVector::Zero();
  for (int j = 1; j < kNumHandJoints; ++j)
    for (int a = 0; a < 3; ++a) angles[3 * (j - 1) + a] = deg[j][a] * kDeg;
  HandParams p;
  p.hand_pose = HandPoseFromAnatomicalAngles(anatomy, angles);
  return p;
}

void Chain(std::array<std::array<double, 3>, kNumHandJoints>* d, int first,
           std::array<double, 3> a, std::array<double, 3> b, std::array<double, 3> c) {
  (*d)[first] = a;
  (*d)[first + 1] = b;
  (*d)[first + 2] = c;
}

}  // namespace

void HandPreviewOptions::Check(const std::string& source) const {
  RequireInRange(source, "tile_size", tile_size, 32, 4096, "32 to 4096 pixels");
  if (views.empty()) throw InputError(source, "views", "at least one view");
  for (const std::string& v : views) {
    if (v != "palm" && v != "back" && v != "thumb" && v != "pinky" && v != "tip") {
      throw InputError(source, "views", "palm, back, thumb, pinky or tip", v);
    }
  }
}

std::vector<NamedHandPose> PreviewHandPoses(const HandModel& model) {
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  using Table = std::array<std::array<double, 3>, kNumHandJoints>;
  std::vector<NamedHandPose> poses;
  poses.push_back({"rest", HandParams()});
  Table fist{};
  for (int first : {1, 4, 7, 10})
    Chain(&fist, first, {0, 0, 85}, {0, 0, 100}, {0, 0, 65});
  Chain(&fist, 13, {10, 15, 35}, {0, 0, 50}, {0, 0, 50});
  poses.push_back({"fist", FromAngles(anatomy, fist)});
  Table pinch{};
  Chain(&pinch, 1, {0, 5, 45}, {0, 0, 50}, {0, 0, 25});
  Chain(&pinch, 4, {0, 0, 25}, {0, 0, 30}, {0, 0, 15});
  Chain(&pinch, 10, {0, -5, 30}, {0, 0, 35}, {0, 0, 20});
  Chain(&pinch, 7, {0, -10, 40}, {0, 0, 40}, {0, 0, 25});
  Chain(&pinch, 13, {20, 35, 30}, {0, 5, 20}, {0, 0, 25});
  poses.push_back({"pinch", FromAngles(anatomy, pinch)});
  Table point = fist;
  Chain(&point, 1, {0, 3, 0}, {0, 0, 0}, {0, 0, 0});
  poses.push_back({"point", FromAngles(anatomy, point)});
  Table spread{};
  Chain(&spread, 1, {0, 15, -5}, {0, 0, 0}, {0, 0, 0});
  Chain(&spread, 4, {0, 2, -5}, {0, 0, 0}, {0, 0, 0});
  Chain(&spread, 10, {0, -12, -5}, {0, 0, 0}, {0, 0, 0});
  Chain(&spread, 7, {0, -20, -5}, {0, 0, 0}, {0, 0, 0});
  Chain(&spread, 13, {0, -10, -10}, {0, 0, -5}, {0, 0, -5});
  poses.push_back({"spread", FromAngles(anatomy, spread)});
  Table grasp{};
  for (int first : {1, 4, 7, 10})
    Chain(&grasp, first, {0, 0, 40}, {0, 0, 45}, {0, 0, 30});
  Chain(&grasp, 13, {15, 30, 25}, {0, 0, 20}, {0, 0, 20});
  poses.push_back({"grasp", FromAngles(anatomy, grasp)});
  return poses;
}

Eigen::Vector3d JointColor(int joint) {
  static const double kColors[kNumHandJoints][3] = {
      {0.75, 0.75, 0.75},                                          // wrist
      {0.90, 0.20, 0.20}, {0.95, 0.55, 0.30}, {1.00, 0.85, 0.55},  // index
      {0.20, 0.65, 0.20}, {0.50, 0.85, 0.35}, {0.80, 1.00, 0.60},  // middle
      {0.55, 0.25, 0.75}, {0.75, 0.50, 0.90}, {0.95, 0.80, 1.00},  // pinky
      {0.15, 0.35, 0.85}, {0.35, 0.65, 0.95}, {0.70, 0.90, 1.00},  // ring
      {0.85, 0.65, 0.05}, {0.95, 0.85, 0.20}, {1.00, 1.00, 0.60},  // thumb
  };
  return Eigen::Vector3d(kColors[joint][0], kColors[joint][1], kColors[joint][2]);
}

ImageU8 RenderHandSheet(const HandModel& model, const std::vector<NamedHandPose>& poses,
                        const HandPreviewOptions& options) {
  options.Check("preview options");
  const int tile = options.tile_size;
  const int cols = static_cast<int>(options.views.size());
  const int rows = static_cast<int>(poses.size());
  ImageU8 sheet(cols * tile, std::max(rows, 1) * tile, 3, 255);
  std::vector<Eigen::Vector3d> colors;
  if (options.coloring == HandPreviewColoring::kSkinningWeights) {
    colors.assign(model.num_vertices(), Eigen::Vector3d::Zero());
    for (int v = 0; v < model.num_vertices(); ++v)
      for (int j = 0; j < kNumHandJoints; ++j)
        colors[v] += model.skinning_weights(v, j) * JointColor(j);
  }
  std::vector<Eigen::Vector3i> faces(model.num_faces());
  for (int f = 0; f < model.num_faces(); ++f) faces[f] = model.faces.row(f).transpose();
  // One scale for the whole sheet: the rest hand's extent fills ~85 % of a tile.
  const HandMesh rest = PoseHand(model, HandParams());
  const Eigen::Vector3d lo = rest.vertices.colwise().minCoeff();
  const Eigen::Vector3d hi = rest.vertices.colwise().maxCoeff();
  const double extent = (hi - lo).maxCoeff();
  const double ppm = 0.85 * tile / extent;
  const double mirror = model.side == HandSide::kLeft ? -1.0 : 1.0;
  for (int r = 0; r < rows; ++r) {
    const HandMesh mesh = PoseHand(model, poses[r].params);
    std::vector<Eigen::Vector3d> vertices(mesh.vertices.rows());
    for (int v = 0; v < mesh.vertices.rows(); ++v) vertices[v] = mesh.vertices.row(v);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    for (int c = 0; c < cols; ++c) {
      const std::string& name = options.views[c];
      Eigen::Vector3d dir;
      Eigen::Vector3d up(-1, 0, 0);  // fingers point up
      if (name == "palm") dir = Eigen::Vector3d(0, 1, 0);
      if (name == "back") dir = Eigen::Vector3d(0, -1, 0);
      if (name == "thumb") dir = Eigen::Vector3d(0, 0, -1);
      if (name == "pinky") dir = Eigen::Vector3d(0, 0, 1);
      if (name == "tip") dir = Eigen::Vector3d(1, 0, 0), up = Eigen::Vector3d(0, 1, 0);
      dir.x() *= mirror;  // the left hand is the mirror image: mirror the camera too
      up.x() *= mirror;
      ImageU8 tile_image(tile, tile, 3, 255);
      DrawMeshOrthographic(vertices, faces, colors, LookAlong(dir, up, centre, ppm),
                           &tile_image);
      Paste(tile_image, c * tile, r * tile, &sheet);
    }
  }
  return sheet;
}

}  // namespace handlabel
