#include "exports/label_series.h"

#include <algorithm>
#include <filesystem>

#include "core/errors.h"

namespace handlabel {

namespace fs = std::filesystem;

namespace {

// The labels/ folder of `dir` when it has one, else `dir` itself.
fs::path LabelFolder(const std::string& dir) {
  const fs::path labels = fs::path(dir) / "labels";
  if (fs::is_directory(labels)) return labels;
  if (!fs::is_directory(dir)) {
    throw InputError(dir, "--labels", "a labeling job's output folder or its labels/",
                     "no such folder");
  }
  return dir;
}

}  // namespace

std::string LabelSeries::FileOf(const std::string& frame) const {
  return (fs::path(labels_dir) / (FrameFileStem(frame, "frame id") + ".json")).string();
}

LabelSeries ReadLabelSeries(const std::string& dir) {
  LabelSeries series;
  const fs::path folder = LabelFolder(dir);
  series.labels_dir = folder.string();
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    // Leftovers of interrupted atomic writes end in .tmp-...; only finished labels count.
    if (entry.is_regular_file() && entry.path().extension() == ".json") {
      files.push_back(entry.path());
    }
  }
  if (files.empty()) {
    throw InputError(series.labels_dir, "labels", "label files <frame>.json", "none");
  }
  for (const fs::path& file : files)
    series.labels.push_back(ReadLabelFile(file.string()));
  std::sort(series.labels.begin(), series.labels.end(),
            [](const LabelRecord& a, const LabelRecord& b) { return a.frame < b.frame; });
  const LabelRecord& first = series.labels.front();
  series.side = first.side;
  series.hand_model = first.provenance.hand_model;
  for (const LabelRecord& label : series.labels) {
    const std::string file = series.FileOf(label.frame);
    if (label.side != series.side) {
      throw InputError(file, "hand_side",
                       HandSideName(series.side) + " as frame " + first.frame + " (one " +
                           "hand per export)",
                       HandSideName(label.side));
    }
    if (label.provenance.hand_model != series.hand_model) {
      throw InputError(file, "provenance.hand_model",
                       "'" + series.hand_model + "' as frame " + first.frame,
                       "'" + label.provenance.hand_model + "'");
    }
  }
  return series;
}

}  // namespace handlabel
