#include "exports/export_labels.h"

#include <filesystem>
#include <fstream>
#include <memory>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "exports/coco_wholebody.h"
#include "exports/dexycb_layout.h"
#include "exports/gltf_animation.h"
#include "exports/ho3d_layout.h"
#include "exports/keypoint_tables.h"
#include "exports/label_series.h"
#include "pipeline/hand_model_source.h"
#include "pipeline/job_config.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_stage_factory.h"

namespace handlabel {

namespace fs = std::filesystem;

namespace {

constexpr ExportFormat kAllFormats[] = {ExportFormat::kNpz,    ExportFormat::kCsv,
                                        ExportFormat::kCoco,   ExportFormat::kGlb,
                                        ExportFormat::kDexYcb, ExportFormat::kHo3d};

// The job that made the labels: --job, else the job file <output.dir>/job.json names.
JobConfig LabelsJob(const ExportRequest& request, const LabelSeries& series) {
  if (!request.job_file.empty()) return LoadJobConfig(request.job_file);
  const std::string stamp =
      JobStampPath(fs::path(series.labels_dir).parent_path().string());
  if (!fs::exists(stamp)) {
    throw InputError("--job", "job file",
                     "the labeling job's YAML (no " + stamp + " names it)", "none");
  }
  std::string job_file;
  try {
    std::ifstream in(stamp);
    job_file = nlohmann::json::parse(in).at("job_file").get<std::string>();
  } catch (const std::exception& e) {
    throw InputError(stamp, "job_file", "the job file that made the labels", e.what());
  }
  if (!fs::exists(job_file)) {
    throw InputError(stamp, "job_file",
                     "a job file that exists from here (else pass --job)",
                     "'" + job_file + "'");
  }
  return LoadJobConfig(job_file);
}

// The labels' hand model: --hand-model, else the job's. Its name must be the one the
// labels record, so that hands_mean is the one the fitter used.
HandModel LabelsHandModel(const ExportRequest& request, const LabelSeries& series) {
  HandModelOrigin origin;
  std::string value = request.hand_model;
  if (value.empty()) {
    const JobConfig job = LabelsJob(request, series);
    value = job.hand_model;
    origin = {job.source_file, "hand_model"};
  }
  HandModel model = ResolveHandModel(value, series.side, origin).model;
  if (model.name != series.hand_model) {
    throw InputError(origin.source, origin.field,
                     "the hand model the labels were made with ('" + series.hand_model +
                         "', provenance.hand_model)",
                     "'" + model.name + "'");
  }
  return model;
}

bool AnyParameters(const LabelSeries& series) {
  for (const LabelRecord& label : series.labels) {
    if (label.params) return true;
  }
  return false;
}

std::string ExportNpz(const ExportRequest& request, const LabelSeries& series) {
  ManoLayerSetting setting;
  setting.convention = request.convention;
  setting.flat_hand_mean =
      request.flat_hand_mean.value_or(DefaultFlatHandMean(request.convention));
  std::optional<HandModel> model;
  if (!setting.flat_hand_mean && AnyParameters(series)) {
    model = LabelsHandModel(request, series);
  }
  WriteKeypointsNpz(series, setting, model ? &*model : nullptr, request.out);
  return "mano parameters for " + ToString(setting.convention) + " with flat_hand_mean " +
         (setting.flat_hand_mean ? "true" : "false");
}

// The job's capture, read as the job reads it, for its cameras and image files only:
// without the detector's 2D.
std::unique_ptr<FrameSource> LabelsCapture(const ExportRequest& request,
                                           const LabelSeries& series) {
  JobConfig job = LabelsJob(request, series);
  job.keypoints_from_detector = false;
  return BuildFrameSource(job);
}

std::string ExportCoco(const ExportRequest& request, const LabelSeries& series) {
  const std::unique_ptr<FrameSource> source = LabelsCapture(request, series);
  const nlohmann::json coco = CocoWholeBodyHands(series, *source);
  WriteFileAtomically(request.out, coco.dump(1) + "\n");
  return std::to_string(coco["images"].size()) + " images, " +
         std::to_string(coco["annotations"].size()) + " hand annotations, cameras of " +
         source->Describe();
}

std::string ExportDataset(const ExportRequest& request, const LabelSeries& series) {
  const DatasetLayoutOptions options{request.out, request.images};
  const SeriesCapture capture =
      ReadSeriesCapture(series, *LabelsCapture(request, series));
  if (request.format == ExportFormat::kHo3d) {
    return WriteHo3dLayout(series, capture, options);
  }
  return WriteDexYcbLayout(series, LabelsHandModel(request, series), capture, options);
}

}  // namespace

std::string ToString(ExportFormat format) {
  switch (format) {
    case ExportFormat::kNpz:
      return "npz";
    case ExportFormat::kCsv:
      return "csv";
    case ExportFormat::kCoco:
      return "coco";
    case ExportFormat::kGlb:
      return "glb";
    case ExportFormat::kDexYcb:
      return "dexycb";
    case ExportFormat::kHo3d:
      return "ho3d";
  }
  return "?";
}

ExportFormat ParseExportFormat(const std::string& text, const std::string& source) {
  for (ExportFormat f : kAllFormats) {
    if (text == ToString(f)) return f;
  }
  throw InputError(source, "format", ExportFormatChoices(), "'" + text + "'");
}

std::string ExportFormatChoices() {
  std::string out;
  for (ExportFormat f : kAllFormats) out += (out.empty() ? "" : " | ") + ToString(f);
  return out;
}

std::string ExportLabels(const ExportRequest& request) {
  const LabelSeries series = ReadLabelSeries(request.labels_dir);
  std::string what;
  switch (request.format) {
    case ExportFormat::kNpz:
      what = ExportNpz(request, series);
      break;
    case ExportFormat::kCsv:
      WriteKeypointsCsv(series, request.out);
      what = "21 keypoints per frame";
      break;
    case ExportFormat::kCoco:
      what = ExportCoco(request, series);
      break;
    case ExportFormat::kGlb: {
      GltfAnimationOptions options;
      options.fps = request.fps;
      WriteFileAtomically(
          request.out,
          HandAnimationGlb(series, LabelsHandModel(request, series), options));
      what = "a skinned hand, " + std::to_string(series.labels.size()) + " keyframes";
      break;
    }
    case ExportFormat::kDexYcb:
    case ExportFormat::kHo3d:
      what = ExportDataset(request, series);
      break;
  }
  return "export: " + std::to_string(series.labels.size()) + " labels of " +
         series.labels_dir + " -> " + request.out + " (" + ToString(request.format) +
         ": " + what + ")";
}

}  // namespace handlabel
