#include "calib/board_calib_report.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "image/draw.h"
#include "image/image.h"

namespace handlabel {

std::string BoardCalibTable(const BoardCalibResult& result) {
  std::ostringstream out;
  out << std::left << std::setw(14) << "camera" << std::right << std::setw(8) << "frames"
      << std::setw(8) << "corners" << std::setw(9) << "outliers" << std::setw(10)
      << "rms px" << std::setw(12) << "init rms" << std::setw(9) << "fx" << std::setw(9)
      << "fy" << std::setw(8) << "cx" << std::setw(8) << "cy"
      << "\n";
  out << std::fixed;
  for (size_t c = 0; c < result.stats.size(); ++c) {
    const CameraCalibStats& s = result.stats[c];
    const Camera& cam = result.rig[c].camera;
    out << std::left << std::setw(14) << s.name << std::right << std::setw(8) << s.frames
        << std::setw(8) << s.observations << std::setw(9) << s.outliers
        << std::setprecision(3) << std::setw(10) << s.rms_px << std::setw(12)
        << s.initial_rms_px << std::setprecision(1) << std::setw(9) << cam.fx()
        << std::setw(9) << cam.fy() << std::setw(8) << cam.cx() << std::setw(8)
        << cam.cy() << "\n";
  }
  out << std::setprecision(3) << "all cameras: rms " << result.rms_px << " px; world "
      << result.world << "\n";
  return out.str();
}

nlohmann::json BoardCalibJson(const BoardCalibResult& result, const BoardSpec& board,
                              const BoardCalibOptions& options) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const CameraCalibStats& s : result.stats) {
    cameras.push_back({{"name", s.name},
                       {"frames", s.frames},
                       {"observations", s.observations},
                       {"outliers", s.outliers},
                       {"rms_px", s.rms_px},
                       {"initial_rms_px", s.initial_rms_px}});
  }
  nlohmann::json tree = nlohmann::json::array();
  for (const auto& [parent, child, weight] : result.tree) {
    tree.push_back({{"parent", parent}, {"child", child}, {"shared_corners", weight}});
  }
  nlohmann::json boards = nlohmann::json::object();
  for (const auto& [key, pose] : result.world_from_board) {
    const Eigen::Quaterniond& q = pose.rotation;
    boards[key] = {{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
                   {"translation",
                    {pose.translation.x(), pose.translation.y(), pose.translation.z()}}};
  }
  return {{"board", board.ToString()}, {"model", CameraModelName(options.model)},
          {"world", result.world},     {"rms_px", result.rms_px},
          {"cameras", cameras},        {"spanning_tree", tree},
          {"world_from_board", boards}};
}

namespace {

constexpr int kResidualPanel = 260;  // pixels, each camera's square panel

// Where camera c's zero residual sits: the middle of its panel, a little lower to leave
// room for the label.
Eigen::Vector2d ResidualOrigin(int c, int cols) {
  return Eigen::Vector2d((c % cols) * kResidualPanel + kResidualPanel / 2,
                         (c / cols) * kResidualPanel + kResidualPanel / 2 + 10);
}

// Frame, axes through zero and the 1 px circle (`scale` pixels per residual pixel).
void DrawResidualFrame(ImageU8* canvas, int c, int cols, double scale) {
  const int x0 = (c % cols) * kResidualPanel, y0 = (c / cols) * kResidualPanel;
  const int x1 = x0 + kResidualPanel - 1, y1 = y0 + kResidualPanel - 1;
  const Rgb frame = {200, 200, 200}, axis = {220, 220, 220};
  DrawLine(canvas, Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0), frame);
  DrawLine(canvas, Eigen::Vector2d(x0, y1), Eigen::Vector2d(x1, y1), frame);
  DrawLine(canvas, Eigen::Vector2d(x0, y0), Eigen::Vector2d(x0, y1), frame);
  DrawLine(canvas, Eigen::Vector2d(x1, y0), Eigen::Vector2d(x1, y1), frame);
  const Eigen::Vector2d o = ResidualOrigin(c, cols);
  const double half = kResidualPanel / 2.0;
  DrawLine(canvas, o - Eigen::Vector2d(half - 10, 0), o + Eigen::Vector2d(half - 10, 0),
           axis);
  DrawLine(canvas, o - Eigen::Vector2d(0, half - 30), o + Eigen::Vector2d(0, half - 10),
           axis);
  DrawRing(canvas, o, static_cast<int>(std::lround(scale)), {150, 150, 150});
}

// The camera's name and "rms 0.112 px, 2903 pts, 27 out" below it, clear of the
// outliers piled on the top of the +-range square (from y = 30 px).
void DrawResidualLabel(ImageU8* canvas, int c, int cols, const CameraCalibStats& s) {
  const int x = (c % cols) * kResidualPanel + 6, y = (c / cols) * kResidualPanel + 3;
  DrawText(canvas, x, y, s.name, {0, 0, 0}, 2);
  std::ostringstream stats;
  stats << "rms " << std::fixed << std::setprecision(3) << s.rms_px << " px, "
        << s.observations << " pts, " << s.outliers << " out";
  DrawText(canvas, x, y + 2 * kFontGlyphHeight + 2, stats.str(), {40, 40, 40});
}

}  // namespace

void PlotBoardResiduals(const BoardCalibResult& result, const std::string& png_path) {
  const int n = static_cast<int>(result.stats.size());
  const int cols = std::min(n, 4), rows = (n + cols - 1) / cols;
  // A strip below the panels for the legend, clear of the outliers on the panel edges.
  constexpr int kLegendHeight = 16;
  ImageU8 canvas(cols * kResidualPanel, rows * kResidualPanel + kLegendHeight, 3, 255);
  // Common scale: 3 x the largest inlier RMS, at least 1 px, fills half a panel.
  double max_rms = 0;
  for (const CameraCalibStats& s : result.stats) max_rms = std::max(max_rms, s.rms_px);
  const double range = std::max(1.0, 3 * max_rms);
  const double scale = (kResidualPanel / 2.0 - 20) / range;
  for (int c = 0; c < n; ++c) DrawResidualFrame(&canvas, c, cols, scale);
  for (const CornerResidual& r : result.residuals) {
    // Residuals beyond the range sit on its edge rather than drop out of the picture.
    const Eigen::Vector2d p = r.residual.cwiseMax(-range).cwiseMin(range) * scale;
    DrawDisc(&canvas, ResidualOrigin(r.camera, cols) + p, 1,
             r.inlier ? Rgb{20, 90, 200} : Rgb{220, 30, 30});
  }
  for (int c = 0; c < n; ++c) DrawResidualLabel(&canvas, c, cols, result.stats[c]);
  std::ostringstream legend;
  legend << "grey circle = 1 px, axes span +-" << std::setprecision(2) << range << " px";
  DrawText(&canvas, 6, rows * kResidualPanel + (kLegendHeight - kFontGlyphHeight) / 2,
           legend.str(), {80, 80, 80});
  WritePng(png_path, canvas);
}

}  // namespace handlabel
