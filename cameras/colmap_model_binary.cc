// COLMAP binary format (little-endian): cameras.bin, images.bin, points3D.bin.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "cameras/colmap_model.h"
#include "cameras/rig_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"

namespace handlabel {
namespace {

static_assert(sizeof(double) == 8, "COLMAP binary files hold IEEE doubles");

// Reads a whole file and hands out little-endian values, failing with the file name,
// the record and the field when the data ends early.
class BinaryReader {
 public:
  explicit BinaryReader(const std::string& path)
      : path_(path), data_(ReadFileBytes(path, "COLMAP binary file")) {}

  void SetRecord(const std::string& record) { record_ = record; }

  template <typename T>
  T Read(const char* field) {
    if (data_.size() - pos_ < sizeof(T)) Truncated(field);
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));  // x86/ARM hosts are LE
    pos_ += sizeof(T);
    return value;
  }
  double ReadDouble(const char* field) {
    const double v = Read<double>(field);
    if (!std::isfinite(v)) {
      throw InputError(path_, Where(field), "a finite number", "NaN/inf");
    }
    return v;
  }
  std::string ReadName(const char* field) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) Truncated(field);
    std::string s = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  // A count of records of at least `min_record_bytes` each; rejects counts that
  // cannot fit in the rest of the file (garbled headers would otherwise allocate
  // absurd amounts).
  uint64_t ReadCount(const char* field, size_t min_record_bytes) {
    const uint64_t n = Read<uint64_t>(field);
    if (min_record_bytes > 0 && n > (data_.size() - pos_) / min_record_bytes) {
      throw InputError(path_, Where(field),
                       "a count that fits the file (" +
                           std::to_string(data_.size() - pos_) + " bytes left)",
                       std::to_string(n));
    }
    return n;
  }
  void ExpectEnd() {
    if (pos_ != data_.size()) {
      throw InputError(path_, "(end)", "no data after the last record",
                       std::to_string(data_.size() - pos_) + " extra bytes");
    }
  }
  const std::string& path() const { return path_; }
  std::string Where(const char* field) const {
    return record_.empty() ? field : record_ + " " + field;
  }

 private:
  [[noreturn]] void Truncated(const char* field) {
    throw InputError(path_, Where(field), "more data (file truncated?)",
                     "end of file at byte " + std::to_string(pos_));
  }
  std::string path_;
  std::string data_;
  size_t pos_ = 0;
  std::string record_;
};

class BinaryWriter {
 public:
  explicit BinaryWriter(const std::string& path)
      : path_(path), out_(path, std::ios::binary) {
    if (!out_) throw InputError(path, "(file)", "a writable path", "cannot open");
  }
  template <typename T>
  void Write(T value) {
    out_.write(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void WriteName(const std::string& s) { out_.write(s.c_str(), s.size() + 1); }
  void Finish() {
    out_.close();
    if (!out_) throw InputError(path_, "(file)", "a successful write", "write failed");
  }

 private:
  std::string path_;
  std::ofstream out_;
};

std::map<uint32_t, ColmapCamera> ReadCamerasBinary(const std::string& path) {
  BinaryReader r(path);
  std::map<uint32_t, ColmapCamera> cameras;
  const uint64_t n = r.ReadCount("num_cameras", 24);
  for (uint64_t i = 0; i < n; ++i) {
    r.SetRecord("camera #" + std::to_string(i));
    ColmapCamera cam;
    cam.id = r.Read<uint32_t>("camera_id");
    r.SetRecord("camera " + std::to_string(cam.id));
    cam.model = CameraModelFromId(r.Read<int32_t>("model_id"), path + " " + r.Where(""));
    cam.width = r.Read<uint64_t>("width");
    cam.height = r.Read<uint64_t>("height");
    CheckedImageSide(cam.width, path, r.Where("width"));
    CheckedImageSide(cam.height, path, r.Where("height"));
    for (int k = 0; k < NumCameraParams(cam.model); ++k) {
      cam.params.push_back(r.ReadDouble("params"));
    }
    if (!cameras.emplace(cam.id, cam).second) {
      throw InputError(path, r.Where("camera_id"), "unique ids", "repeated");
    }
  }
  r.ExpectEnd();
  return cameras;
}

std::map<uint32_t, ColmapImage> ReadImagesBinary(const std::string& path) {
  BinaryReader r(path);
  std::map<uint32_t, ColmapImage> images;
  const uint64_t n = r.ReadCount("num_reg_images", 4 + 56 + 4 + 1 + 8);
  for (uint64_t i = 0; i < n; ++i) {
    r.SetRecord("image #" + std::to_string(i));
    ColmapImage image;
    image.id = r.Read<uint32_t>("image_id");
    r.SetRecord("image " + std::to_string(image.id));
    double q[4], t[3];
    for (double& v : q) v = r.ReadDouble("qvec");
    for (double& v : t) v = r.ReadDouble("tvec");
    const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
    if (rotation.norm() < 1e-6) {
      throw InputError(path, r.Where("qvec"), "a non-zero quaternion", "zero");
    }
    image.cam_from_world = Rigid3(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
    image.camera_id = r.Read<uint32_t>("camera_id");
    image.name = r.ReadName("name");
    const uint64_t num_points = r.ReadCount("num_points2D", 24);
    image.points2D.reserve(num_points);
    image.point3D_ids.reserve(num_points);
    for (uint64_t k = 0; k < num_points; ++k) {
      const double x = r.ReadDouble("point2D x");
      const double y = r.ReadDouble("point2D y");
      image.points2D.emplace_back(x, y);
      image.point3D_ids.push_back(r.Read<uint64_t>("point3D_id"));
    }
    if (!images.emplace(image.id, image).second) {
      throw InputError(path, r.Where("image_id"), "unique ids", "repeated");
    }
  }
  r.ExpectEnd();
  return images;
}

std::map<uint64_t, ColmapPoint3D> ReadPointsBinary(const std::string& path) {
  BinaryReader r(path);
  std::map<uint64_t, ColmapPoint3D> points;
  const uint64_t n = r.ReadCount("num_points3D", 8 + 24 + 3 + 8 + 8);
  for (uint64_t i = 0; i < n; ++i) {
    r.SetRecord("point3D #" + std::to_string(i));
    ColmapPoint3D point;
    point.id = r.Read<uint64_t>("point3D_id");
    r.SetRecord("point3D " + std::to_string(point.id));
    for (int k = 0; k < 3; ++k) point.xyz[k] = r.ReadDouble("xyz");
    for (int k = 0; k < 3; ++k) point.rgb[k] = r.Read<uint8_t>("rgb");
    point.error = r.Read<double>("error");
    const uint64_t length = r.ReadCount("track_length", 8);
    point.track.resize(length);
    for (ColmapTrackElement& e : point.track) {
      e.image_id = r.Read<uint32_t>("track image_id");
      e.point2D_idx = r.Read<uint32_t>("track point2D_idx");
    }
    if (!points.emplace(point.id, point).second) {
      throw InputError(path, r.Where("point3D_id"), "unique ids", "repeated");
    }
  }
  r.ExpectEnd();
  return points;
}

}  // namespace

ColmapModel ReadColmapBinary(const std::string& dir) {
  namespace fs = std::filesystem;
  ColmapModel model;
  model.cameras = ReadCamerasBinary((fs::path(dir) / "cameras.bin").string());
  model.images = ReadImagesBinary((fs::path(dir) / "images.bin").string());
  const fs::path points = fs::path(dir) / "points3D.bin";
  if (fs::exists(points)) model.points3D = ReadPointsBinary(points.string());
  CheckColmapModel(model, dir);
  return model;
}

void WriteColmapBinary(const ColmapModel& model, const std::string& dir) {
  namespace fs = std::filesystem;
  {
    BinaryWriter w((fs::path(dir) / "cameras.bin").string());
    w.Write<uint64_t>(model.cameras.size());
    for (const auto& [id, cam] : model.cameras) {
      w.Write<uint32_t>(id);
      w.Write<int32_t>(static_cast<int32_t>(cam.model));
      w.Write<uint64_t>(cam.width);
      w.Write<uint64_t>(cam.height);
      for (double p : cam.params) w.Write<double>(p);
    }
    w.Finish();
  }
  {
    BinaryWriter w((fs::path(dir) / "images.bin").string());
    w.Write<uint64_t>(model.images.size());
    for (const auto& [id, image] : model.images) {
      const Eigen::Quaterniond& q = image.cam_from_world.rotation;
      const Eigen::Vector3d& t = image.cam_from_world.translation;
      w.Write<uint32_t>(id);
      for (double v : {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()})
        w.Write<double>(v);
      w.Write<uint32_t>(image.camera_id);
      w.WriteName(image.name);
      w.Write<uint64_t>(image.points2D.size());
      for (size_t k = 0; k < image.points2D.size(); ++k) {
        w.Write<double>(image.points2D[k].x());
        w.Write<double>(image.points2D[k].y());
        w.Write<uint64_t>(image.point3D_ids[k]);
      }
    }
    w.Finish();
  }
  {
    BinaryWriter w((fs::path(dir) / "points3D.bin").string());
    w.Write<uint64_t>(model.points3D.size());
    for (const auto& [id, p] : model.points3D) {
      w.Write<uint64_t>(id);
      for (int k = 0; k < 3; ++k) w.Write<double>(p.xyz[k]);
      for (int k = 0; k < 3; ++k) w.Write<uint8_t>(p.rgb[k]);
      w.Write<double>(p.error);
      w.Write<uint64_t>(p.track.size());
      for (const ColmapTrackElement& e : p.track) {
        w.Write<uint32_t>(e.image_id);
        w.Write<uint32_t>(e.point2D_idx);
      }
    }
    w.Finish();
  }
}

}  // namespace handlabel
