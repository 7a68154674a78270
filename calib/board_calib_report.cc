#include "calib/board_calib_report.h"

#include <cmath>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "calib/cv_image_file.h"
#include "core/errors.h"

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

void PlotBoardResiduals(const BoardCalibResult& result, const std::string& png_path) {
  const int n = static_cast<int>(result.stats.size());
  const int cols = std::min(n, 4), rows = (n + cols - 1) / cols;
  const int panel = 260;
  cv::Mat canvas(rows * panel, cols * panel, CV_8UC3, cv::Scalar(255, 255, 255));
  // Common scale: 3 x the largest inlier RMS, at least 1 px, fills half a panel.
  double max_rms = 0;
  for (const CameraCalibStats& s : result.stats) max_rms = std::max(max_rms, s.rms_px);
  const double range = std::max(1.0, 3 * max_rms);
  const double scale = (panel / 2.0 - 20) / range;
  for (int c = 0; c < n; ++c) {
    const cv::Point origin((c % cols) * panel + panel / 2,
                           (c / cols) * panel + panel / 2 + 10);
    cv::rectangle(canvas, cv::Rect((c % cols) * panel, (c / cols) * panel, panel, panel),
                  cv::Scalar(200, 200, 200));
    cv::line(canvas, origin - cv::Point(panel / 2 - 10, 0),
             origin + cv::Point(panel / 2 - 10, 0), cv::Scalar(220, 220, 220));
    cv::line(canvas, origin - cv::Point(0, panel / 2 - 30),
             origin + cv::Point(0, panel / 2 - 10), cv::Scalar(220, 220, 220));
    cv::circle(canvas, origin, static_cast<int>(std::lround(scale)),
               cv::Scalar(150, 150, 150), 1, cv::LINE_AA);
  }
  for (const CornerResidual& r : result.residuals) {
    const cv::Point origin((r.camera % cols) * panel + panel / 2,
                           (r.camera / cols) * panel + panel / 2 + 10);
    const Eigen::Vector2d p = r.residual.cwiseMax(-range).cwiseMin(range) * scale;
    cv::circle(canvas,
               origin + cv::Point(static_cast<int>(p.x()), static_cast<int>(p.y())), 1,
               r.inlier ? cv::Scalar(200, 90, 20) : cv::Scalar(30, 30, 220), cv::FILLED);
  }
  for (int c = 0; c < n; ++c) {
    const CameraCalibStats& s = result.stats[c];
    std::ostringstream label;
    label << s.name << ": rms " << std::fixed << std::setprecision(3) << s.rms_px
          << " px, " << s.observations << " pts, " << s.outliers << " out";
    cv::putText(canvas, label.str(),
                cv::Point((c % cols) * panel + 6, (c / cols) * panel + 16),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  std::ostringstream legend;
  legend << "grey circle = 1 px; axes span +-" << std::setprecision(2) << range << " px";
  cv::putText(canvas, legend.str(), cv::Point(6, rows * panel - 6),
              cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
  WriteCvImage(canvas, png_path);
}

}  // namespace handlabel
