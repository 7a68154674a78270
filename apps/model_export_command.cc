// `handlabel model export`: a hand model's mesh in one of the preview poses, with
// optional shape coefficients, as PLY or OBJ (to look at in MeshLab or Blender).

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "apps/model_file_flags.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "hand/hand_lbs.h"
#include "hand/hand_model_io.h"
#include "hand/hand_preview.h"
#include "pipeline/label_record.h"

namespace handlabel {

int RunModelExport(int argc, char** argv) {
  CLI::App app(
      "Write a hand model's mesh (vertices in metres, the model's own frame) in a named "
      "pose as PLY or OBJ; the format follows the --out extension.",
      "model export");
  std::string path, out, pose = "rest";
  std::vector<double> betas;
  ModelFileFlags flags;
  app.add_option("model", path, "model file (MANO .pkl, smplx .npz or handlabel .npz)")
      ->required();
  app.add_option("--out", out, "mesh file to write: NAME.ply or NAME.obj")->required();
  app.add_option("--pose", pose, "rest, fist, pinch, point, spread or grasp")
      ->capture_default_str();
  app.add_option("--betas", betas, "shape coefficients b1,b2,... (missing ones are 0)")
      ->delimiter(',');
  flags.Register(app);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("model export", [&] {
    const std::string extension = std::filesystem::path(out).extension().string();
    if (extension != ".ply" && extension != ".obj") {
      throw InputError("--out", "extension", ".ply or .obj", out);
    }
    const HandModel model = LoadHandModelFile(path, flags.Options()).model;
    if (static_cast<int>(betas.size()) > model.num_betas()) {
      throw InputError("--betas", "count",
                       "at most " + std::to_string(model.num_betas()) + " values",
                       std::to_string(betas.size()));
    }
    HandParams params;
    bool found = false;
    for (const NamedHandPose& named : PreviewHandPoses(model)) {
      if (named.name == pose) params = named.params, found = true;
    }
    if (!found) {
      throw InputError("--pose", "pose", "rest, fist, pinch, point, spread or grasp",
                       pose);
    }
    params.betas = Eigen::Map<const Eigen::VectorXd>(betas.data(), betas.size());
    const HandMesh mesh = PoseHand(model, params);
    WriteFileAtomically(out, extension == ".ply" ? MeshToPly(mesh.vertices, model.faces)
                                                 : MeshToObj(mesh.vertices, model.faces));
    std::cout << "wrote " << out << " (" << mesh.vertices.rows() << " vertices, "
              << model.num_faces() << " faces, pose " << pose << ")\n";
    return 0;
  });
}

}  // namespace handlabel
