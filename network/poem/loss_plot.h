#pragma once
// Training curves of a run folder (network/poem/poem_trainer.h): loss.csv and
// validation.csv drawn as one PNG with image/line_plot.h.

#include <string>
#include <vector>

#include "image/image.h"

namespace handlabel {

// A CSV file with a header row and numeric cells (non-numbers become NaN).
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  // The values of one column; empty if there is no such column.
  std::vector<double> Column(const std::string& name) const;
};
// Throws InputError naming the path if it cannot be read. Missing file = empty table.
CsvTable ReadCsvTable(const std::string& path);

// Top: total loss and the main terms against the step (log scale); bottom: validation
// MPJPE and MPVPE in mm. Empty tables give empty panels.
ImageU8 DrawTrainingCurves(const CsvTable& loss, const CsvTable& validation);

// Reads run_dir/loss.csv and run_dir/validation.csv and writes run_dir/loss.png
// (`png_path` if not empty).
void DrawTrainingCurves(const std::string& run_dir, const std::string& png_path = "");

}  // namespace handlabel
