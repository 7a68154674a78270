#include "calib/rig_plot.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "calib/cv_image_file.h"
#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

// An orthonormal viewing basis derived from the rig itself, so that plots read the
// same whatever the world frame is (master camera, board, dataset frame).
struct ViewBasis {
  Eigen::Vector3d right, forward, up;
};

ViewBasis RigBasis(const Rig& rig) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero(), view = Eigen::Vector3d::Zero();
  for (const RigCamera& c : rig.cameras()) {
    const Eigen::Matrix3d world_from_cam =
        c.cam_from_world.rotation.conjugate().toRotationMatrix();
    up -= world_from_cam.col(1);
    view += world_from_cam.col(2);
  }
  up = up.norm() > 1e-6 ? up.normalized() : Eigen::Vector3d(0, -1, 0);
  Eigen::Vector3d forward = view - view.dot(up) * up;
  if (forward.norm() < 1e-3 * std::max<size_t>(rig.size(), 1)) {
    // Cameras facing each other (a ring): any horizontal direction will do.
    forward = up.unitOrthogonal();
  }
  forward.normalize();
  return {forward.cross(up), forward, up};
}

cv::Scalar CameraColor(size_t i, size_t n) {
  cv::Mat hsv(1, 1, CV_8UC3,
              cv::Scalar(static_cast<int>(180.0 * i / std::max<size_t>(n, 1)), 200, 200));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

struct Frustum {
  Eigen::Vector3d centre;
  Eigen::Vector3d corners[4];
};

Frustum MakeFrustum(const RigCamera& c, double depth) {
  Frustum f;
  f.centre = c.CenterInWorld();
  const double w = c.camera.width(), h = c.camera.height();
  const Eigen::Vector2d pixels[4] = {
      {-0.5, -0.5}, {w - 0.5, -0.5}, {w - 0.5, h - 0.5}, {-0.5, h - 0.5}};
  const Rigid3 world_from_cam = c.cam_from_world.Inverse();
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector3d ray = c.camera.Unproject(pixels[k]);
    if (!ray.allFinite() || ray.head<2>().norm() > 10) {  // wide fisheye corners
      ray = Eigen::Vector3d((pixels[k].x() - c.camera.cx()) / c.camera.fx(),
                            (pixels[k].y() - c.camera.cy()) / c.camera.fy(), 1.0);
    }
    f.corners[k] = world_from_cam * (ray * depth);
  }
  return f;
}

// Maps 2D plot coordinates (metres) into one panel with a uniform scale.
class Panel {
 public:
  Panel(cv::Mat image, const std::vector<Eigen::Vector2d>& extent_points, int margin)
      : image_(image), margin_(margin) {
    Eigen::Vector2d lo(1e30, 1e30), hi(-1e30, -1e30);
    for (const Eigen::Vector2d& p : extent_points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Eigen::Vector2d size = (hi - lo).cwiseMax(Eigen::Vector2d(0.05, 0.05));
    const double usable = image.cols - 2 * margin;
    scale_ = usable / std::max(size.x(), size.y());
    mid_ = (lo + hi) / 2;
  }
  cv::Point ToPixel(const Eigen::Vector2d& p) const {
    const double x = image_.cols / 2.0 + (p.x() - mid_.x()) * scale_;
    const double y = image_.rows / 2.0 - (p.y() - mid_.y()) * scale_;
    return cv::Point(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
  }
  double scale() const { return scale_; }
  cv::Mat& image() { return image_; }

 private:
  cv::Mat image_;
  int margin_;
  double scale_ = 1;
  Eigen::Vector2d mid_;
};

// A round scale-bar length (1, 2 or 5 x 10^k metres) about a fifth of the panel.
double NiceLength(double metres) {
  const double p = std::pow(10.0, std::floor(std::log10(metres)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * p >= metres) return m * p;
  }
  return 10 * p;
}

std::string FormatLength(double m) {
  std::ostringstream s;
  if (m >= 1) {
    s << m << " m";
  } else if (m >= 0.01) {
    s << m * 100 << " cm";
  } else {
    s << m * 1000 << " mm";
  }
  return s.str();
}

void DrawPanel(Panel& panel, const std::vector<Frustum>& frusta, const Rig& rig,
               const std::vector<Eigen::Vector3d>& points,
               const std::function<Eigen::Vector2d(const Eigen::Vector3d&)>& to2d,
               const std::string& label, const std::string& axes) {
  cv::Mat& img = panel.image();
  for (const Eigen::Vector3d& p : points) {
    cv::circle(img, panel.ToPixel(to2d(p)), 2, cv::Scalar(120, 120, 120), cv::FILLED,
               cv::LINE_AA);
  }
  // World origin.
  cv::drawMarker(img, panel.ToPixel(to2d(Eigen::Vector3d::Zero())), cv::Scalar(0, 0, 0),
                 cv::MARKER_CROSS, 14, 1, cv::LINE_AA);
  for (size_t i = 0; i < frusta.size(); ++i) {
    const cv::Scalar color = CameraColor(i, frusta.size());
    const Frustum& f = frusta[i];
    const cv::Point c = panel.ToPixel(to2d(f.centre));
    for (int k = 0; k < 4; ++k) {
      const cv::Point a = panel.ToPixel(to2d(f.corners[k]));
      const cv::Point b = panel.ToPixel(to2d(f.corners[(k + 1) % 4]));
      cv::line(img, c, a, color, 1, cv::LINE_AA);
      cv::line(img, a, b, color, 2, cv::LINE_AA);
    }
    cv::circle(img, c, 3, color, cv::FILLED, cv::LINE_AA);
    cv::putText(img, rig[i].name, c + cv::Point(5, -5), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
  }
  cv::putText(img, label, cv::Point(10, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, axes, cv::Point(10, 42), cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
  const double bar = NiceLength(img.cols / 5.0 / panel.scale());
  const int bar_px = static_cast<int>(std::lround(bar * panel.scale()));
  const cv::Point start(10, img.rows - 15);
  cv::line(img, start, start + cv::Point(bar_px, 0), cv::Scalar(0, 0, 0), 2);
  cv::putText(img, FormatLength(bar), start + cv::Point(bar_px + 6, 4),
              cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

double AutoDepth(const Rig& rig) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
  for (const RigCamera& c : rig.cameras()) {
    lo = lo.cwiseMin(c.CenterInWorld());
    hi = hi.cwiseMax(c.CenterInWorld());
  }
  return std::max(0.05, 0.2 * (hi - lo).maxCoeff());
}

}  // namespace

void RigPlotOptions::Check(const std::string& source) const {
  RequireInRange(source, "panel_size", panel_size, 100, 4000, "100..4000 pixels");
  if (!std::isfinite(frustum_depth)) {
    throw InputError(source, "frustum_depth", "a finite number (<= 0 = auto)");
  }
}

void PlotRig(const Rig& rig, const std::string& png_path, const RigPlotOptions& options) {
  options.Check("RigPlotOptions");
  HL_CHECK(!rig.empty(), "plotting an empty rig");
  const double depth = options.frustum_depth > 0 ? options.frustum_depth : AutoDepth(rig);
  std::vector<Frustum> frusta;
  for (const RigCamera& c : rig.cameras()) frusta.push_back(MakeFrustum(c, depth));
  const ViewBasis basis = RigBasis(rig);
  const auto top = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(p.dot(basis.right), p.dot(basis.forward));
  };
  const auto side = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(p.dot(basis.forward), p.dot(basis.up));
  };
  const int n = options.panel_size;
  const int title_height = options.title.empty() ? 0 : 30;
  cv::Mat canvas(n + title_height, 2 * n, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int view = 0; view < 2; ++view) {
    const auto& to2d = view == 0
                           ? std::function<Eigen::Vector2d(const Eigen::Vector3d&)>(top)
                           : std::function<Eigen::Vector2d(const Eigen::Vector3d&)>(side);
    std::vector<Eigen::Vector2d> extent;
    for (const Frustum& f : frusta) {
      extent.push_back(to2d(f.centre));
      for (const Eigen::Vector3d& c : f.corners) extent.push_back(to2d(c));
    }
    for (const Eigen::Vector3d& p : options.points) extent.push_back(to2d(p));
    extent.push_back(to2d(Eigen::Vector3d::Zero()));
    Panel panel(canvas(cv::Rect(view * n, title_height, n, n)), extent, 60);
    DrawPanel(panel, frusta, rig, options.points, to2d,
              view == 0 ? "from above" : "from the side",
              view == 0 ? "horizontal: rig right, vertical: rig forward"
                        : "horizontal: rig forward, vertical: rig up");
  }
  cv::line(canvas, cv::Point(n, title_height), cv::Point(n, n + title_height),
           cv::Scalar(180, 180, 180));
  if (!options.title.empty()) {
    cv::putText(canvas, options.title, cv::Point(10, 21), cv::FONT_HERSHEY_SIMPLEX, 0.6,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  WriteCvImage(canvas, png_path);
}

std::string RigTable(const Rig& rig) {
  std::ostringstream out;
  out << std::left << std::setw(14) << "camera" << std::setw(15) << "model"
      << std::setw(10) << "size" << std::right << std::setw(9) << "fx" << std::setw(9)
      << "fy" << std::setw(8) << "cx" << std::setw(8) << "cy" << std::setw(10) << "|dist|"
      << std::setw(24) << "centre (m)" << std::setw(21) << "looks along" << std::setw(10)
      << "nearest"
      << "\n";
  out << std::fixed;
  for (const RigCamera& c : rig.cameras()) {
    const Camera& cam = c.camera;
    double dist = 0;
    for (size_t i = 0; i < cam.params().size(); ++i) {
      const bool is_distortion = (cam.model() == CameraModelId::kSimpleRadial ||
                                  cam.model() == CameraModelId::kRadial)
                                     ? i >= 3
                                     : i >= 4;
      if (is_distortion) dist = std::max(dist, std::abs(cam.params()[i]));
    }
    const Eigen::Vector3d centre = c.CenterInWorld();
    const Eigen::Vector3d view =
        c.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ();
    double nearest = std::numeric_limits<double>::infinity();
    for (const RigCamera& other : rig.cameras()) {
      if (&other != &c)
        nearest = std::min(nearest, (other.CenterInWorld() - centre).norm());
    }
    std::ostringstream size, centre_text, view_text;
    size << cam.width() << "x" << cam.height();
    centre_text << std::fixed << std::setprecision(3) << std::showpos << centre.x() << " "
                << centre.y() << " " << centre.z();
    view_text << std::fixed << std::setprecision(2) << std::showpos << view.x() << " "
              << view.y() << " " << view.z();
    out << std::left << std::setw(14) << c.name << std::setw(15)
        << CameraModelName(cam.model()) << std::setw(10) << size.str() << std::right
        << std::setprecision(1) << std::setw(9) << cam.fx() << std::setw(9) << cam.fy()
        << std::setw(8) << cam.cx() << std::setw(8) << cam.cy() << std::setprecision(4)
        << std::setw(10) << dist << std::setw(24) << centre_text.str() << std::setw(21)
        << view_text.str() << std::setprecision(3) << std::setw(10);
    if (std::isfinite(nearest)) {
      out << nearest;
    } else {
      out << "-";
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace handlabel
