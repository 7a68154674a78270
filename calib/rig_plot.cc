#include "calib/rig_plot.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <sstream>

#include "core/errors.h"
#include "core/option_checks.h"
#include "image/draw.h"
#include "image/image.h"

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

// Camera i of n: hues evenly around the colour wheel at saturation and value 200/255
// (OpenCV's HSV picture of the earlier plots), so neighbours in the list differ.
Rgb CameraColor(size_t i, size_t n) {
  const double sextant = 6.0 * i / std::max<size_t>(n, 1);
  const double value = 200, chroma = value * 200 / 255;
  const double x = chroma * (1 - std::abs(std::fmod(sextant, 2.0) - 1));
  const double rgb[6][3] = {{chroma, x, 0}, {x, chroma, 0}, {0, chroma, x},
                            {0, x, chroma}, {x, 0, chroma}, {chroma, 0, x}};
  const double* c = rgb[std::min(static_cast<int>(sextant), 5)];
  const auto level = [&](double v) {
    return static_cast<uint8_t>(std::lround(v + value - chroma));
  };
  return {level(c[0]), level(c[1]), level(c[2])};
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

// One square panel of its own (so that drawing is clipped to it), mapping 2D plot
// coordinates (metres) to pixels with one scale for both axes.
class Panel {
 public:
  Panel(int size, const std::vector<Eigen::Vector2d>& extent_points, int margin)
      : image_(size, size, 3, 255) {
    Eigen::Vector2d lo(1e30, 1e30), hi(-1e30, -1e30);
    for (const Eigen::Vector2d& p : extent_points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Eigen::Vector2d size_m = (hi - lo).cwiseMax(Eigen::Vector2d(0.05, 0.05));
    scale_ = (size - 2 * margin) / std::max(size_m.x(), size_m.y());
    mid_ = (lo + hi) / 2;
  }
  // Rounded to whole pixels, so that lines meeting at a point start on the same pixel.
  Eigen::Vector2d ToPixel(const Eigen::Vector2d& p) const {
    return Eigen::Vector2d(std::round(image_.width / 2.0 + (p.x() - mid_.x()) * scale_),
                           std::round(image_.height / 2.0 - (p.y() - mid_.y()) * scale_));
  }
  double scale() const { return scale_; }
  ImageU8& image() { return image_; }

 private:
  ImageU8 image_;
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

using PlotProjection = std::function<Eigen::Vector2d(const Eigen::Vector3d&)>;

const Rgb kBlack = {0, 0, 0};

// Rays from the centre to the far corners, the far rectangle thicker and a dot on the
// centre.
void DrawFrustum(Panel& panel, const Frustum& f, const PlotProjection& to2d,
                 const Rgb& color) {
  ImageU8* img = &panel.image();
  const Eigen::Vector2d c = panel.ToPixel(to2d(f.centre));
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = panel.ToPixel(to2d(f.corners[k]));
    const Eigen::Vector2d b = panel.ToPixel(to2d(f.corners[(k + 1) % 4]));
    DrawLine(img, c, a, color);
    DrawThickLine(img, a, b, 2.5, color);
  }
  DrawDisc(img, c, 3, color);
}

// Camera names above and right of their centres, after all frusta and on a white
// outline (all outlines first), so that no line runs through a letter.
void DrawCameraNames(Panel& panel, const std::vector<Frustum>& frusta, const Rig& rig,
                     const PlotProjection& to2d) {
  constexpr int kScale = 2;
  for (const bool outline : {true, false}) {
    for (size_t i = 0; i < frusta.size(); ++i) {
      const Eigen::Vector2d c = panel.ToPixel(to2d(frusta[i].centre));
      const int x = static_cast<int>(c.x()) + 6;
      const int y = static_cast<int>(c.y()) - 6 - kScale * kFontGlyphHeight;
      for (int d = 0; d < (outline ? 9 : 1); ++d) {
        const int dx = outline ? d % 3 - 1 : 0, dy = outline ? d / 3 - 1 : 0;
        DrawText(&panel.image(), x + dx, y + dy, rig[i].name,
                 outline ? Rgb{255, 255, 255} : Rgb{40, 40, 40}, kScale);
      }
    }
  }
}

// The panel's name and axes at the top, a scale bar at the bottom.
void DrawPanelText(Panel& panel, const std::string& label, const std::string& axes) {
  ImageU8* img = &panel.image();
  DrawText(img, 10, 10, label, kBlack, 2);
  DrawText(img, 10, 32, axes, {80, 80, 80});
  const double bar = NiceLength(img->width / 5.0 / panel.scale());
  const double bar_px = std::round(bar * panel.scale());
  const Eigen::Vector2d start(10, img->height - 15);
  DrawLine(img, start, start + Eigen::Vector2d(bar_px, 0), kBlack, 2);
  DrawText(img, static_cast<int>(start.x() + bar_px) + 8,
           static_cast<int>(start.y()) - kFontGlyphHeight + 1, FormatLength(bar), kBlack,
           2);
}

void DrawPanel(Panel& panel, const std::vector<Frustum>& frusta, const Rig& rig,
               const std::vector<Eigen::Vector3d>& points, const PlotProjection& to2d,
               const std::string& label, const std::string& axes) {
  ImageU8* img = &panel.image();
  for (const Eigen::Vector3d& p : points) {
    DrawDisc(img, panel.ToPixel(to2d(p)), 1.5, {150, 150, 150});
  }
  // World origin: a cross.
  const Eigen::Vector2d origin = panel.ToPixel(to2d(Eigen::Vector3d::Zero()));
  DrawLine(img, origin - Eigen::Vector2d(7, 0), origin + Eigen::Vector2d(7, 0), kBlack);
  DrawLine(img, origin - Eigen::Vector2d(0, 7), origin + Eigen::Vector2d(0, 7), kBlack);
  for (size_t i = 0; i < frusta.size(); ++i) {
    DrawFrustum(panel, frusta[i], to2d, CameraColor(i, frusta.size()));
  }
  DrawCameraNames(panel, frusta, rig, to2d);
  DrawPanelText(panel, label, axes);
}

// Copies `panel` into `canvas` with its top-left pixel at (x0, y0).
void Paste(const ImageU8& panel, int x0, int y0, ImageU8* canvas) {
  for (int y = 0; y < panel.height; ++y) {
    std::copy_n(&panel.at(0, y), size_t(panel.width) * panel.channels,
                &canvas->at(x0, y0 + y));
  }
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
  ImageU8 canvas(2 * n, n + title_height, 3, 255);
  for (int view = 0; view < 2; ++view) {
    const PlotProjection to2d = view == 0 ? PlotProjection(top) : PlotProjection(side);
    std::vector<Eigen::Vector2d> extent;
    for (const Frustum& f : frusta) {
      extent.push_back(to2d(f.centre));
      for (const Eigen::Vector3d& c : f.corners) extent.push_back(to2d(c));
    }
    for (const Eigen::Vector3d& p : options.points) extent.push_back(to2d(p));
    extent.push_back(to2d(Eigen::Vector3d::Zero()));
    Panel panel(n, extent, 60);
    DrawPanel(panel, frusta, rig, options.points, to2d,
              view == 0 ? "from above" : "from the side",
              view == 0 ? "horizontal: rig right, vertical: rig forward"
                        : "horizontal: rig forward, vertical: rig up");
    Paste(panel.image(), view * n, title_height, &canvas);
  }
  DrawLine(&canvas, Eigen::Vector2d(n, title_height),
           Eigen::Vector2d(n, n + title_height - 1), {180, 180, 180});
  if (!options.title.empty()) DrawText(&canvas, 10, 8, options.title, kBlack, 2);
  WritePng(png_path, canvas);
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
