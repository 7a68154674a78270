// `handlabel model <subcommand>`: inspect and convert hand model files.
// Subcommands sit in one table (ModelSubcommands below): to add one, write a
// RunModelFoo(argc, argv) with its own CLI11 app and add a row.

#include <Eigen/Core>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "apps/model_file_flags.h"
#include "core/errors.h"
#include "hand/hand_lbs.h"
#include "hand/hand_model_io.h"
#include "hand/hand_skeleton.h"
#include "openhand/builder.h"

namespace handlabel {
namespace {

void PrintInfo(const std::string& path, const LoadedHandModel& loaded,
               std::ostream& out) {
  const HandModel& m = loaded.model;
  HandParams rest;
  rest.betas = Eigen::VectorXd::Zero(m.num_betas());
  const HandMesh mesh = PoseHand(m, rest);
  const Eigen::Vector3d extent =
      (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff())
          .transpose();
  const double wrist_to_middle_tip =
      (mesh.keypoints.row(12) - mesh.keypoints.row(0)).norm();

  out << std::fixed << std::setprecision(2);
  out << "file:          " << path << "\n"
      << "format:        " << HandModelFormatName(loaded.format) << "\n"
      << "name:          " << m.name << "\n"
      << "side:          " << HandSideName(m.side) << "\n"
      << "vertices:      " << m.num_vertices() << "\n"
      << "faces:         " << m.num_faces() << "\n"
      << "joints:        " << kNumHandJoints << " (+5 fingertips = 21 keypoints)\n"
      << "betas:         " << m.num_betas() << "\n"
      << "pose PCA:      ";
  if (m.pose_pca_basis.size() == 0) {
    out << "none\n";
  } else {
    out << m.pose_pca_basis.rows() << " components"
        << (m.pose_mean.size() ? ", with hand mean" : ", no hand mean") << "\n";
  }
  out << "J_regressor:   " << m.joint_regressor.nonZeros() << " non-zeros\n"
      << "size at rest:  wrist to middle fingertip " << 100 * wrist_to_middle_tip
      << " cm; bounding box " << 100 * extent.x() << " x " << 100 * extent.y() << " x "
      << 100 * extent.z() << " cm\n"
      << "fingertips:    vertices";
  for (int t : m.tip_vertex_ids) out << " " << t;
  out << " (thumb, index, middle, ring, pinky)\n"
      << "keypoints (SNAP/OpenPose order <- native joint, or tip vertex):\n";
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    out << "  " << std::setw(2) << k << " " << std::left << std::setw(11)
        << kSnapKeypointNames[k] << std::right << " <- ";
    if (native < kNumHandJoints) {
      out << "joint " << native << "\n";
    } else {
      out << "tip vertex " << m.tip_vertex_ids[native - kNumHandJoints] << "\n";
    }
  }
}

int RunModelInfo(int argc, char** argv) {
  CLI::App app(
      "Print a hand model's statistics: format, side, vertex / face / beta counts, pose "
      "PCA, fingertip vertices, the 21-keypoint map and its size at rest.",
      "model info");
  std::string path;
  ModelFileFlags flags;
  app.add_option("file", path, "model file (MANO .pkl, smplx .npz or handlabel .npz)")
      ->required();
  flags.Register(app);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("model info", [&] {
    PrintInfo(path, LoadHandModelFile(path, flags.Options()), std::cout);
    return 0;
  });
}

// --side and --tips for files that record their own: the loader keeps the file's, so
// convert applies them here rather than ignoring them. A side other than the file's
// mirrors the model (x -> -x). Returns what changed, for the closing line.
std::string ApplyModelFileFlags(const ModelFileFlags& flags, HandModel* model) {
  std::string changes;
  const HandModelLoadOptions options = flags.Options();
  if (options.side && *options.side != model->side) {
    *model = MirrorHandModel(*model);
    changes += ", mirrored: the file records the other side";
  }
  if (options.tip_vertex_ids && *options.tip_vertex_ids != model->tip_vertex_ids) {
    for (const int id : *options.tip_vertex_ids) {
      if (id < 0 || id >= model->num_vertices()) {
        throw InputError("--tips", "fingertip vertex ids",
                         "ids in [0, " + std::to_string(model->num_vertices()) + ")",
                         std::to_string(id));
      }
    }
    model->tip_vertex_ids = *options.tip_vertex_ids;
    changes += ", fingertips from --tips";
  }
  return changes;
}

int RunModelConvert(int argc, char** argv) {
  CLI::App app(
      "Convert any supported hand model file (MANO pickle, re-saved pickle, smplx npz) "
      "into the handlabel model file (a smplx-style .npz with handlabel_* metadata).",
      "model convert");
  std::string in, out;
  ModelFileFlags flags;
  app.add_option("input", in, "model file to read")->required();
  app.add_option("output", out, "handlabel model file to write (.npz)")->required();
  flags.Register(app);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("model convert", [&] {
    LoadedHandModel loaded = LoadHandModelFile(in, flags.Options());
    const std::string changes = ApplyModelFileFlags(flags, &loaded.model);
    SaveHandModel(loaded.model, out);
    std::cout << "wrote " << out << " (" << loaded.model.name << ", "
              << HandSideName(loaded.model.side) << ", " << loaded.model.num_vertices()
              << " vertices, from " << HandModelFormatName(loaded.format) << changes
              << ")\n";
    return 0;
  });
}

struct ModelSubcommand {
  const char* name;
  const char* summary;
  int (*run)(int argc, char** argv);
};

const std::vector<ModelSubcommand>& ModelSubcommands() {
  static const std::vector<ModelSubcommand> table = {
      {"info", "print a model file's statistics", RunModelInfo},
      {"convert", "convert a MANO / smplx model file to the handlabel format",
       RunModelConvert},
      {"build", "build the open hand model (ours, MANO-compatible)", RunModelBuild},
      {"render", "render a preview sheet (PNG) of a model in several poses",
       RunModelRender},
      {"export", "write the mesh in a named pose and shape as PLY or OBJ",
       RunModelExport},
      {"detector-keypoints",
       "learn where a 2D detector's keypoints lie on the hand (synthetic captures)",
       RunModelDetectorKeypoints},
  };
  return table;
}

void PrintModelUsage(std::ostream& out) {
  out << "Usage: handlabel model <subcommand> [options]\n"
         "       handlabel model <subcommand> --help\n\n"
         "Subcommands:\n";
  for (const ModelSubcommand& s : ModelSubcommands()) {
    std::string name = s.name;
    name.resize(std::max<size_t>(name.size(), 10), ' ');
    out << "  " << name << "  " << s.summary << "\n";
  }
  out << "\nSee docs/hand-model-files.md.\n";
}

}  // namespace

int RunModel(int argc, char** argv) {
  if (argc < 2) {
    PrintModelUsage(std::cerr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintModelUsage(std::cout);
    return 0;
  }
  for (const ModelSubcommand& s : ModelSubcommands()) {
    if (name == s.name) return s.run(argc - 1, argv + 1);
  }
  std::cerr << "handlabel model: unknown subcommand '" << name << "'\n";
  PrintModelUsage(std::cerr);
  return 2;
}

}  // namespace handlabel
