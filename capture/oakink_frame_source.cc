#include "capture/oakink_frame_source.h"

#include <filesystem>

#include "cameras/dataset_calib.h"
#include "core/errors.h"
#include "formats/pickle_reader.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// "<seq>__<ts>__<sbj>__<frame>__<cam>" -> its five parts, or empty.
std::vector<std::string> SplitName(const std::string& stem) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t end = stem.find("__", start);
    parts.push_back(stem.substr(start, end == std::string::npos ? end : end - start));
    if (end == std::string::npos) break;
    start = end + 2;
  }
  for (const std::string& part : parts) {
    if (part.empty()) return {};
  }
  return parts.size() == 5 ? parts : std::vector<std::string>{};
}

// A pickled array of `cols` columns (and `rows` rows when > 0), or nullopt when the
// file does not exist.
std::optional<Points3d> ReadPoints(const fs::path& file, int rows) {
  if (!fs::is_regular_file(file)) return std::nullopt;
  const PickleValue value = ReadPickleFile(file.string());
  if (value.kind != PickleValue::Kind::kArray || value.array->ndim() != 2 ||
      value.array->shape[1] != 3 || (rows > 0 && value.array->shape[0] != rows)) {
    throw InputError(
        file.string(), "(pickle)",
        rows > 0 ? "a " + std::to_string(rows) + " x 3 array" : "an N x 3 array",
        value.Describe());
  }
  const std::vector<double> v = value.array->ToDoubles();
  Points3d points(value.array->shape[0], 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    points.row(i) << v[3 * i], v[3 * i + 1], v[3 * i + 2];
  return points;
}

}  // namespace

std::string OakInkStreamName(const std::string& cam) {
  static const char* kStreams[] = {"north_east_color", "south_east_color",
                                   "north_west_color", "south_west_color"};
  if (cam.size() == 1 && cam[0] >= '0' && cam[0] <= '3') return kStreams[cam[0] - '0'];
  return cam;
}

OakInkFrameSource::OakInkFrameSource(const std::string& path,
                                     const std::optional<Rig>& cameras)
    : path_(path), cameras_(cameras) {
  const fs::path p(path);
  if (fs::is_directory(p / "anno" / "general_info")) {
    image_dir_ = p.string();
  } else if (fs::is_directory(p / "image" / "anno" / "general_info")) {
    image_dir_ = (p / "image").string();
  } else {
    throw InputError(path, "input.path",
                     "OakInk's image folder (with anno/general_info) or the folder "
                     "holding it",
                     fs::exists(p) ? "no anno/general_info" : "not found");
  }
  const fs::path info = fs::path(image_dir_) / "anno" / "general_info";
  for (const auto& entry : fs::directory_iterator(info)) {
    if (entry.path().extension() != ".pkl") continue;
    const std::string stem = entry.path().stem().string();
    const std::vector<std::string> parts = SplitName(stem);
    if (parts.empty()) {
      throw InputError(entry.path().string(), "(file name)",
                       "<seq>__<ts>__<sbj>__<frame>__<cam>.pkl", stem + ".pkl");
    }
    cams_[stem.substr(0, stem.size() - parts[4].size() - 2)].push_back(parts[4]);
  }
  if (cams_.empty()) {
    throw InputError(info.string(), "(pickles)", "OakInk general_info pickles",
                     "none found");
  }
  for (auto& [group, cams] : cams_) std::sort(cams.begin(), cams.end());
}

std::vector<std::string> OakInkFrameSource::FrameIds() const {
  std::vector<std::string> ids;
  for (const auto& [group, cams] : cams_) ids.push_back(group);
  return ids;  // std::map keeps them sorted
}

std::string OakInkFrameSource::Describe() const {
  return "OakInk-Image " + image_dir_ + " (" + std::to_string(cams_.size()) +
         " frames, " + std::to_string(cams_.begin()->second.size()) +
         " cameras in the first, right hand, 2D keypoints: none, masks: none, ground "
         "truth: anno/hand_j and hand_v where present)";
}

FrameInput OakInkFrameSource::Load(const std::string& id) const {
  const auto it = cams_.find(id);
  if (it == cams_.end()) {
    throw InputError(image_dir_ + "/anno/general_info", "frame id",
                     "<seq>__<ts>__<sbj>__<frame> of a general_info pickle",
                     "'" + id + "'");
  }
  const std::vector<std::string> parts = SplitName(id + "__cam");
  const fs::path dir(image_dir_);
  FrameInput frame;
  frame.id = id;
  for (const std::string& cam : it->second) {
    const std::string name = id + "__" + cam + ".pkl";
    frame.rig.Add(cameras_ ? cameras_->Find(cam)  // InputError lists the known names
                           : ReadOakInkCamera(
                                 (dir / "anno" / "general_info" / name).string(), cam));
    const fs::path image = dir / "stream_release_v2" / parts[0] / parts[1] /
                           (OakInkStreamName(cam) + "_" + parts[3] + ".png");
    if (!fs::is_regular_file(image)) {
      throw InputError(image.string(),
                       "stream_release_v2/<seq>/<ts>/<stream>_<frame>.png",
                       "camera " + cam + "'s image of frame " + id, "missing");
    }
    frame.image_paths.push_back(image.string());
  }
  for (size_t v = 0; v < it->second.size() && !frame.ground_truth; ++v) {
    const std::string name = id + "__" + it->second[v] + ".pkl";
    const std::optional<Points3d> joints =
        ReadPoints(dir / "anno" / "hand_j" / name, kNumHandKeypoints);
    if (!joints) continue;
    const Rigid3 world_from_cam = frame.rig[v].cam_from_world.Inverse();
    FrameGroundTruth truth;
    truth.keypoints = TransformPoints(world_from_cam, *joints);
    if (const std::optional<Points3d> vertices =
            ReadPoints(dir / "anno" / "hand_v" / name, 0))
      truth.vertices = TransformPoints(world_from_cam, *vertices);
    frame.ground_truth = truth;
  }
  return frame;
}

}  // namespace handlabel
