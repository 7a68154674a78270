#pragma once
// `handlabel export`: a labeling job's labels in another format (docs/exports.md).
// Chooses what each format needs: the hand model (for a layer that adds hands_mean,
// and the glb's mesh and skeleton)
// and the capture (for 2D projections), from the flags or from the job that made the
// labels (<output.dir>/job.json names its job file).

#include <optional>
#include <string>

#include "exports/dataset_frames.h"
#include "exports/mano_convention.h"

namespace handlabel {

enum class ExportFormat { kNpz, kCsv, kCoco, kGlb, kDexYcb, kHo3d };
// "npz" | "csv" | "coco" | "glb" | "dexycb" | "ho3d"
std::string ToString(ExportFormat format);
// Throws InputError naming `source` for another name.
ExportFormat ParseExportFormat(const std::string& text, const std::string& source);
std::string ExportFormatChoices();  // "npz | csv | ... | ho3d"

struct ExportRequest {
  std::string labels_dir;  // the job's output.dir (or its labels/ folder)
  ExportFormat format = ExportFormat::kNpz;
  std::string out;  // the file to write (dexycb, ho3d: the dataset folder)
  ManoConvention convention = ManoConvention::kSmplx;
  std::optional<bool> flat_hand_mean;  // nullopt: the convention's layer default
  std::string hand_model;  // "": the job's hand_model (then the usual resolution)
  double fps = 30;         // glb: keyframes per second
  std::string job_file;    // "": the job file job.json names
  ImagePlacement images = ImagePlacement::kLink;  // dexycb, ho3d: the capture's images
};

// Writes request.out; returns one line saying what was written. Throws InputError
// naming the flag, file or field that is missing or wrong.
std::string ExportLabels(const ExportRequest& request);

}  // namespace handlabel
