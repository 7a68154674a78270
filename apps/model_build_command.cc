// `handlabel model build` and `handlabel model render`: the project's open hand model
// (openhand/builder.h) and preview pictures of any hand model.

#include <iostream>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/errors.h"
#include "hand/hand_model_io.h"
#include "hand/hand_preview.h"
#include "image/image.h"
#include "openhand/builder.h"
#include "openhand/mesh_checks.h"

namespace handlabel {

int RunModelBuild(int argc, char** argv) {
  CLI::App app(
      "Build the open hand model (MANO-compatible, ours, redistributable) from its "
      "anthropometric design and save it in the handlabel model format. The same "
      "options give the same file, byte for byte; the defaults reproduce "
      "models/open_hand_{right,left}.npz.",
      "model build");
  std::string side = "right", out;
  OpenHandBuildOptions options;
  app.add_option("--side", side, "right or left (the left hand is the exact mirror)")
      ->check(
          CLI::IsMember({HandSideName(HandSide::kLeft), HandSideName(HandSide::kRight)}));
  app.add_option("--out", out, "model file to write (.npz)")->required();
  app.add_option("--seed", options.seed, "seed of the shape and pose sampling")
      ->capture_default_str();
  app.add_option("--grid-step", options.grid_step,
                 "marching-tetrahedra grid spacing in metres")
      ->capture_default_str();
  app.add_option("--vertices", options.target_vertices, "vertex count after decimation")
      ->capture_default_str();
  app.add_option("--betas", options.num_betas, "shape components")->capture_default_str();
  app.add_option("--shape-samples", options.num_shape_samples,
                 "sampled designs for the shape PCA")
      ->capture_default_str();
  app.add_option("--pose-samples", options.num_pose_samples,
                 "sampled natural poses for the pose PCA")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("model build", [&] {
    options.side = ParseHandSide(side, "--side", "value");
    OpenHandBuildReport report;
    const HandModel model = BuildOpenHand(DefaultOpenHandDesign(), options, &report);
    SaveHandModel(model, out);
    const MeshTopology topo = AnalyzeMeshTopology(model.num_vertices(), model.faces);
    HandParams rest;
    const HandMesh mesh = PoseHand(model, rest);
    std::cout << "wrote " << out << " (" << model.name << ": " << model.num_vertices()
              << " vertices, " << model.num_faces() << " faces, " << model.num_betas()
              << " betas)\n"
              << "  closed manifold: " << (topo.IsClosedManifold() ? "yes" : "NO")
              << "; wrist to middle fingertip "
              << 100.0 * (mesh.keypoints.row(12) - mesh.keypoints.row(0)).norm()
              << " cm\n"
              << "  fine mesh " << report.fine_vertices << " vertices; shape PCA keeps "
              << 100.0 * report.shape_variance_explained << " % of the variance\n"
              << "  joint regressor error: " << 1e3 * report.max_regressor_error_mean
              << " mm (mean shape), " << 1e3 * report.max_regressor_error
              << " mm (worst shape direction)\n"
              << "  pose PCA: first 6 components hold "
              << 100.0 * report.pose_variance_explained_6 << " % of the variance\n";
    return 0;
  });
}

int RunModelRender(int argc, char** argv) {
  CLI::App app(
      "Render a preview sheet (PNG) of a hand model: one row per pose (rest, fist, "
      "pinch, point, spread, grasp), one column per view.",
      "model render");
  std::string path, out, coloring = "skin";
  HandPreviewOptions options;
  std::vector<std::string> poses;
  app.add_option("model", path, "model file (MANO .pkl, smplx .npz or handlabel .npz)")
      ->required();
  app.add_option("--out", out, "PNG file to write")->required();
  app.add_option("--tile", options.tile_size, "tile size in pixels")
      ->capture_default_str();
  app.add_option("--views", options.views, "columns: palm, back, thumb, pinky, tip")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--poses", poses,
                 "rows (default all): rest, fist, pinch, point, spread, grasp")
      ->delimiter(',');
  app.add_option("--color", coloring, "skin, or weights (skinning weights per joint)")
      ->check(CLI::IsMember({"skin", "weights"}))
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("model render", [&] {
    const HandModel model = LoadHandModel(path);
    options.coloring = coloring == "weights" ? HandPreviewColoring::kSkinningWeights
                                             : HandPreviewColoring::kSkin;
    std::vector<NamedHandPose> all = PreviewHandPoses(model), chosen;
    for (const std::string& name : poses) {
      bool found = false;
      for (const NamedHandPose& p : all) {
        if (p.name == name) chosen.push_back(p), found = true;
      }
      if (!found)
        throw InputError("--poses", "pose", "rest, fist, pinch, point, spread or grasp",
                         name);
    }
    if (chosen.empty()) chosen = all;
    WritePng(out, RenderHandSheet(model, chosen, options));
    std::cout << "wrote " << out << " (" << chosen.size() << " poses x "
              << options.views.size() << " views)\n";
    return 0;
  });
}

}  // namespace handlabel
