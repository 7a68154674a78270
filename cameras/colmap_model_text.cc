// COLMAP text format: cameras.txt, images.txt, points3D.txt.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "cameras/colmap_model.h"
#include "cameras/rig_json.h"
#include "core/errors.h"

namespace handlabel {
namespace {

// Reads whitespace-separated tokens of one line, naming file and line on errors.
class LineReader {
 public:
  LineReader(const std::string& path, int line_number, const std::string& line)
      : path_(path), where_("line " + std::to_string(line_number)), in_(line) {}

  template <typename T>
  T Next(const char* field) {
    std::string token;
    if (!(in_ >> token))
      throw InputError(path_, where_ + " " + field, "a value", "end of line");
    std::istringstream parse(token);
    T value;
    if constexpr (std::is_unsigned_v<T>) {
      if (!token.empty() && token[0] == '-') {
        throw InputError(path_, where_ + " " + field, "a non-negative integer", token);
      }
    }
    if (!(parse >> value) || !parse.eof()) {
      throw InputError(path_, where_ + " " + field, "a number", "'" + token + "'");
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) {
        throw InputError(path_, where_ + " " + field, "a finite number", token);
      }
    }
    return value;
  }
  std::string NextString(const char* field) {
    std::string token;
    if (!(in_ >> token))
      throw InputError(path_, where_ + " " + field, "a value", "end of line");
    return token;
  }
  bool AtEnd() {
    in_ >> std::ws;
    return in_.eof();
  }
  const std::string& where() const { return where_; }

 private:
  const std::string& path_;
  std::string where_;
  std::istringstream in_;
};

std::ifstream OpenText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "(file)", "a readable COLMAP text file", "cannot open");
  return in;
}

bool IsDataLine(std::string& line) {
  const size_t start = line.find_first_not_of(" \t\r");
  if (start == std::string::npos || line[start] == '#') return false;
  return true;
}

std::map<uint32_t, ColmapCamera> ReadCamerasText(const std::string& path) {
  std::ifstream in = OpenText(path);
  std::map<uint32_t, ColmapCamera> cameras;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!IsDataLine(line)) continue;
    LineReader r(path, n, line);
    ColmapCamera cam;
    cam.id = r.Next<uint32_t>("CAMERA_ID");
    cam.model = CameraModelFromName(r.NextString("MODEL"), path + " " + r.where());
    cam.width = r.Next<uint64_t>("WIDTH");
    CheckedImageSide(cam.width, path, r.where() + " WIDTH");
    cam.height = r.Next<uint64_t>("HEIGHT");
    CheckedImageSide(cam.height, path, r.where() + " HEIGHT");
    const int num_params = NumCameraParams(cam.model);
    for (int i = 0; i < num_params; ++i) cam.params.push_back(r.Next<double>("PARAMS"));
    if (!r.AtEnd()) {
      throw InputError(
          path, r.where() + " PARAMS",
          std::to_string(num_params) + " values for " + CameraModelName(cam.model),
          "more");
    }
    if (!cameras.emplace(cam.id, cam).second) {
      throw InputError(path, r.where() + " CAMERA_ID", "unique ids",
                       std::to_string(cam.id) + " twice");
    }
  }
  return cameras;
}

std::map<uint32_t, ColmapImage> ReadImagesText(const std::string& path) {
  std::ifstream in = OpenText(path);
  std::map<uint32_t, ColmapImage> images;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!IsDataLine(line)) continue;
    LineReader r(path, n, line);
    ColmapImage image;
    image.id = r.Next<uint32_t>("IMAGE_ID");
    double q[4], t[3];
    for (double& v : q) v = r.Next<double>("QW QX QY QZ");
    for (double& v : t) v = r.Next<double>("TX TY TZ");
    const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
    if (rotation.norm() < 1e-6) {
      throw InputError(path, r.where() + " QW QX QY QZ", "a non-zero quaternion", "zero");
    }
    image.cam_from_world = Rigid3(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
    image.camera_id = r.Next<uint32_t>("CAMERA_ID");
    image.name = r.NextString("NAME");
    std::string points_line;
    if (!std::getline(in, points_line)) {
      throw InputError(path, "line " + std::to_string(n + 1) + " POINTS2D",
                       "a second line for image " + std::to_string(image.id),
                       "end of file");
    }
    ++n;
    LineReader p(path, n, points_line);
    while (!p.AtEnd()) {
      const double x = p.Next<double>("POINTS2D X");
      const double y = p.Next<double>("POINTS2D Y");
      const long long id = p.Next<long long>("POINTS2D POINT3D_ID");
      if (id < -1)
        throw InputError(path, p.where() + " POINT3D_ID", "-1 or an id",
                         std::to_string(id));
      image.points2D.emplace_back(x, y);
      image.point3D_ids.push_back(id == -1 ? kColmapNoPoint3D
                                           : static_cast<uint64_t>(id));
    }
    if (!images.emplace(image.id, image).second) {
      throw InputError(path, r.where() + " IMAGE_ID", "unique ids",
                       std::to_string(image.id) + " twice");
    }
  }
  return images;
}

std::map<uint64_t, ColmapPoint3D> ReadPointsText(const std::string& path) {
  std::ifstream in = OpenText(path);
  std::map<uint64_t, ColmapPoint3D> points;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!IsDataLine(line)) continue;
    LineReader r(path, n, line);
    ColmapPoint3D point;
    point.id = r.Next<uint64_t>("POINT3D_ID");
    for (int i = 0; i < 3; ++i) point.xyz[i] = r.Next<double>("X Y Z");
    for (int i = 0; i < 3; ++i) {
      const int c = r.Next<int>("R G B");
      if (c < 0 || c > 255)
        throw InputError(path, r.where() + " R G B", "0-255", std::to_string(c));
      point.rgb[i] = static_cast<uint8_t>(c);
    }
    point.error = r.Next<double>("ERROR");
    while (!r.AtEnd()) {
      ColmapTrackElement e;
      e.image_id = r.Next<uint32_t>("TRACK IMAGE_ID");
      e.point2D_idx = r.Next<uint32_t>("TRACK POINT2D_IDX");
      point.track.push_back(e);
    }
    if (!points.emplace(point.id, point).second) {
      throw InputError(path, r.where() + " POINT3D_ID", "unique ids",
                       std::to_string(point.id) + " twice");
    }
  }
  return points;
}

std::ofstream CreateText(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "(file)", "a writable path", "cannot open");
  out << std::setprecision(17);
  return out;
}

void Finish(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw InputError(path, "(file)", "a successful write", "write failed");
}

}  // namespace

ColmapModel ReadColmapText(const std::string& dir) {
  namespace fs = std::filesystem;
  ColmapModel model;
  model.cameras = ReadCamerasText((fs::path(dir) / "cameras.txt").string());
  model.images = ReadImagesText((fs::path(dir) / "images.txt").string());
  const fs::path points = fs::path(dir) / "points3D.txt";
  if (fs::exists(points)) model.points3D = ReadPointsText(points.string());
  CheckColmapModel(model, dir);
  return model;
}

void WriteColmapText(const ColmapModel& model, const std::string& dir) {
  namespace fs = std::filesystem;
  {
    const std::string path = (fs::path(dir) / "cameras.txt").string();
    std::ofstream out = CreateText(path);
    out << "# Camera list with one line of data per camera:\n"
        << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        << "# Number of cameras: " << model.cameras.size() << "\n";
    for (const auto& [id, cam] : model.cameras) {
      out << id << " " << CameraModelName(cam.model) << " " << cam.width << " "
          << cam.height;
      for (double p : cam.params) out << " " << p;
      out << "\n";
    }
    Finish(out, path);
  }
  {
    const std::string path = (fs::path(dir) / "images.txt").string();
    std::ofstream out = CreateText(path);
    out << "# Image list with two lines of data per image:\n"
        << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
        << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
        << "# Number of images: " << model.images.size() << "\n";
    for (const auto& [id, image] : model.images) {
      const Eigen::Quaterniond& q = image.cam_from_world.rotation;
      const Eigen::Vector3d& t = image.cam_from_world.translation;
      out << id << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " "
          << t.x() << " " << t.y() << " " << t.z() << " " << image.camera_id << " "
          << image.name << "\n";
      for (size_t i = 0; i < image.points2D.size(); ++i) {
        if (i > 0) out << " ";
        out << image.points2D[i].x() << " " << image.points2D[i].y() << " ";
        if (image.point3D_ids[i] == kColmapNoPoint3D) {
          out << -1;
        } else {
          out << image.point3D_ids[i];
        }
      }
      out << "\n";
    }
    Finish(out, path);
  }
  {
    const std::string path = (fs::path(dir) / "points3D.txt").string();
    std::ofstream out = CreateText(path);
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << "# Number of points: " << model.points3D.size() << "\n";
    for (const auto& [id, p] : model.points3D) {
      out << id << " " << p.xyz.x() << " " << p.xyz.y() << " " << p.xyz.z() << " "
          << int(p.rgb[0]) << " " << int(p.rgb[1]) << " " << int(p.rgb[2]) << " "
          << p.error;
      for (const ColmapTrackElement& e : p.track) {
        out << " " << e.image_id << " " << e.point2D_idx;
      }
      out << "\n";
    }
    Finish(out, path);
  }
}

}  // namespace handlabel
