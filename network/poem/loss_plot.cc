#include "network/poem/loss_plot.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "image/line_plot.h"

namespace handlabel {
namespace {

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) cells.push_back(cell);
  return cells;
}

}  // namespace

std::vector<double> CsvTable::Column(const std::string& name) const {
  std::vector<double> out;
  for (size_t c = 0; c < columns.size(); ++c) {
    if (columns[c] != name) continue;
    for (const auto& row : rows) out.push_back(c < row.size() ? row[c] : NAN);
  }
  return out;
}

CsvTable ReadCsvTable(const std::string& path) {
  CsvTable table;
  if (!std::filesystem::exists(path)) return table;
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "a readable CSV file", "cannot open");
  std::string line;
  if (std::getline(in, line)) table.columns = SplitCsvLine(line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    for (const std::string& cell : SplitCsvLine(line)) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      row.push_back(end != cell.c_str() ? v : NAN);
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

ImageU8 DrawTrainingCurves(const CsvTable& loss, const CsvTable& validation) {
  const std::vector<double> steps = loss.Column("step");
  std::vector<PlotSeries> losses;
  int color = 0;
  for (const char* name : {"total", "heatmap_joints", "triangulated_joints", "joints_3d",
                           "vertices_3d", "joints_2d", "masks"}) {
    PlotSeries s;
    s.name = name;
    s.x = steps;
    s.y = loss.Column(name);
    s.color = PlotColor(color++);
    if (!s.y.empty()) losses.push_back(std::move(s));
  }
  PlotOptions top;
  top.title = "training loss";
  top.x_label = "step";
  top.y_label = "loss (log)";
  top.log_y = true;
  top.height = 420;
  const std::vector<double> vsteps = validation.Column("step");
  std::vector<PlotSeries> errors;
  PlotSeries j{"MPJPE mm", vsteps, validation.Column("mpjpe_mm"), PlotColor(0)};
  PlotSeries v{"MPVPE mm", vsteps, validation.Column("mpvpe_mm"), PlotColor(1)};
  if (!j.y.empty()) errors.push_back(j);
  if (!v.y.empty()) errors.push_back(v);
  PlotOptions bottom;
  bottom.title = "validation (held-out synthetic frames)";
  bottom.x_label = "step";
  bottom.y_label = "mm (log)";
  bottom.log_y = true;
  bottom.height = 320;
  if (!steps.empty()) {
    top.x_min = bottom.x_min = 0;
    top.x_max = bottom.x_max = steps.back();
  }
  return StackVertically({DrawLinePlot(losses, top), DrawLinePlot(errors, bottom)});
}

void DrawTrainingCurves(const std::string& run_dir, const std::string& png_path) {
  const std::filesystem::path dir(run_dir);
  const ImageU8 image =
      DrawTrainingCurves(ReadCsvTable((dir / "loss.csv").string()),
                         ReadCsvTable((dir / "validation.csv").string()));
  const std::string out = png_path.empty() ? (dir / "loss.png").string() : png_path;
  WriteFileAtomically(out, EncodePng(image));  // a viewer never sees half a PNG
}

}  // namespace handlabel
