#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "exports/export_labels.h"

namespace handlabel {

int RunExport(int argc, char** argv) {
  CLI::App app(
      "Write a labeling job's labels in another format (docs/exports.md): npz "
      "(keypoints, joints, vertices and MANO parameters per frame, in smplx's, "
      "manopth's or manotorch's convention), csv (21 keypoints per frame) or coco "
      "(COCO-WholeBody-style 2D hand keypoints and boxes per view, projected with the "
      "capture's cameras), glb (a skinned hand in glTF 2.0 with one animation over the "
      "labels), dexycb or ho3d (per-frame annotations in DexYCB's or HO3D's layout, "
      "with the capture's cameras and images, readable by their toolkits and our "
      "in-place readers).\n"
      "Example: handlabel export --labels /tmp/demo_out --format npz --out "
      "/tmp/demo_out/keypoints.npz --mano-convention manopth",
      "export");
  ExportRequest request;
  std::string format, convention = "smplx", flat;
  app.add_option("--labels", request.labels_dir,
                 "the labeling job's output folder (output.dir) or its labels/ folder")
      ->required();
  app.add_option("--format", format, ExportFormatChoices())->required();
  app.add_option("--out", request.out,
                 "the file to write (dexycb, ho3d: the dataset folder)")
      ->required();
  app.add_option("--mano-convention", convention,
                 "npz: MANO parameters for smplx.MANO, manopth.ManoLayer or manotorch's "
                 "ManoLayer (default smplx)")
      ->check(CLI::IsMember({"smplx", "manopth", "manotorch"}));
  app.add_option(
         "--flat-hand-mean", flat,
         "npz: the layer's flat_hand_mean; false subtracts the model's hands_mean "
         "from hand_pose (default: the layer's own, smplx false, manopth and manotorch "
         "true)")
      ->check(CLI::IsMember({"true", "false"}));
  app.add_option("--hand-model", request.hand_model,
                 "npz with --flat-hand-mean false, glb: the labels' hand model file, "
                 "and dexycb (its pose PCA) (default: the job's hand_model)");
  app.add_option("--fps", request.fps, "glb: keyframes per second (default 30)");
  app.add_option("--job", request.job_file,
                 "the job that made the labels (default: the one output.dir/job.json "
                 "names); coco, dexycb and ho3d read its capture's cameras and images");
  std::string images = "link";
  app.add_option("--images", images,
                 "dexycb, ho3d: link (symbolic links, the default) or copy the "
                 "capture's image files into the layout")
      ->check(CLI::IsMember({"link", "copy"}));
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("export", [&] {
    request.format = ParseExportFormat(format, "--format");
    request.convention = ParseManoConvention(convention, "--mano-convention");
    if (!flat.empty()) request.flat_hand_mean = flat == "true";
    request.images = ParseImagePlacement(images, "--images");
    std::cout << ExportLabels(request) << "\n";
    return 0;
  });
}

}  // namespace handlabel
