#include "capture/ho3d_frame_source.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include "cameras/dataset_calib.h"
#include "core/errors.h"
#include "formats/pickle_reader.h"
#include "hand/hand_model.h"
#include "image/image_file.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// HO3D's calibration folder of sequence `name`, next to the split folders.
fs::path CalibrationDir(const fs::path& split_dir, const std::string& name) {
  return split_dir.parent_path() / "calibration" / name / "calibration";
}

fs::path Normalized(const std::string& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // trailing '/'
  return p;
}

// <camera>/rgb/<fid>.jpg, or .png (HO3D v2 style); "" if neither exists.
std::string ImageFile(const std::string& camera_dir, const std::string& fid) {
  for (const char* extension : {".jpg", ".png"}) {
    const fs::path file = fs::path(camera_dir) / "rgb" / (fid + extension);
    if (fs::is_regular_file(file)) return file.string();
  }
  return "";
}

// handJoints3D of one camera's meta pickle in OpenCV axes and SNAP order, or nullopt
// when the file or the annotation is absent (HO3D's evaluation split keeps only the
// root joint).
std::optional<Points3d> JointsInCamera(const fs::path& meta) {
  if (!fs::is_regular_file(meta)) return std::nullopt;
  const PickleValue root = ReadPickleFile(meta.string());
  if (root.kind != PickleValue::Kind::kDict) {
    throw InputError(meta.string(), "(pickle)", "a dict (HO3D meta file)",
                     root.Describe());
  }
  const PickleValue* joints = root.Find("handJoints3D");
  if (!joints || joints->kind != PickleValue::Kind::kArray ||
      joints->array->shape != std::vector<int64_t>{kNumHandKeypoints, 3}) {
    return std::nullopt;
  }
  const std::vector<double> v = joints->array->ToDoubles();
  Points3d out(kNumHandKeypoints, 3);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int n = kSnapFromNative[k];
    // OpenGL camera axes (y up, z backwards) -> OpenCV: diag(1, -1, -1).
    out.row(k) << v[3 * n], -v[3 * n + 1], -v[3 * n + 2];
  }
  return out;
}

// <camera>/seg/<fid>.png (or .jpg, HO3D v2); "" if neither exists.
std::string SegmentationFile(const std::string& camera_dir, const std::string& fid) {
  for (const char* extension : {".png", ".jpg"}) {
    const fs::path file = fs::path(camera_dir) / "seg" / (fid + extension);
    if (fs::is_regular_file(file)) return file.string();
  }
  return "";
}

// HO3D's segmentation picture, as its scripts read it with OpenCV (BGR): channel 0
// (blue) is the hand, channel 1 (green) the object; a pixel counts above 127 (the
// mask rule of image/mask_image.h; JPEG-compressed segmentations are not exactly 0/255).
// Resampled (nearest pixel) to the camera's size when it differs.
void ReadHo3dSegmentation(const std::string& file, const Camera& camera, MaskImage* hand,
                          MaskImage* object) {
  const ImageU8 seg = ReadImageFile(file);
  if (seg.channels < 3) {
    throw InputError(file, "(channels)", "an RGB segmentation (blue hand, green object)",
                     std::to_string(seg.channels) + " channel(s)");
  }
  hand->setZero(camera.height(), camera.width());
  object->setZero(camera.height(), camera.width());
  for (int y = 0; y < camera.height(); ++y) {
    const int sy =
        static_cast<int>(static_cast<int64_t>(y) * seg.height / camera.height());
    for (int x = 0; x < camera.width(); ++x) {
      const int sx =
          static_cast<int>(static_cast<int64_t>(x) * seg.width / camera.width());
      const size_t at = seg.index(sx, sy, 0);
      (*hand)(y, x) = seg.data[at + 2] > 127 ? 255 : 0;  // RGB order: blue is last
      (*object)(y, x) = seg.data[at + 1] > 127 ? 255 : 0;
    }
  }
}

}  // namespace

Ho3dSequence ReadHo3dSequence(const std::string& split_dir, const std::string& name) {
  const fs::path split = Normalized(split_dir);
  const fs::path calibration = CalibrationDir(split, name);
  if (!fs::is_directory(calibration)) {
    throw InputError(calibration.string(), "(folder)",
                     "the multi-camera calibration of HO3D sequence " + name,
                     "not found");
  }
  Ho3dSequence seq;
  seq.name = name;
  seq.rig = ReadDatasetRig("ho3d", calibration.string());  // cameras <SEQ><i>
  std::set<std::string> frames;
  for (const RigCamera& camera : seq.rig.cameras()) {
    const fs::path dir = split / camera.name;
    if (!fs::is_directory(dir / "rgb")) {
      throw InputError((dir / "rgb").string(), "(folder)",
                       "the images of camera " + camera.name + " (listed by " +
                           (calibration / "cam_orders.txt").string() + ")",
                       "not found");
    }
    for (const auto& entry : fs::directory_iterator(dir / "rgb")) {
      const std::string extension = entry.path().extension().string();
      if (extension == ".jpg" || extension == ".png")
        frames.insert(entry.path().stem().string());
    }
    seq.camera_dirs.push_back(dir.string());
  }
  if (frames.empty()) {
    throw InputError(split.string() + "/" + name + "<i>/rgb", "(images)",
                     "<fid>.jpg frames", "none");
  }
  seq.frames.assign(frames.begin(), frames.end());
  return seq;
}

Ho3dFrameSource::Ho3dFrameSource(const std::string& path,
                                 const std::optional<Rig>& cameras)
    : path_(path) {
  const fs::path p = Normalized(path);
  if (fs::is_directory(p.parent_path()) &&
      fs::is_directory(p.parent_path().parent_path() / "calibration" / p.filename())) {
    sequences_.push_back(ReadHo3dSequence(p.parent_path().string(), p.filename()));
  } else if (fs::is_directory(p) && fs::is_directory(p.parent_path() / "calibration")) {
    // A split folder: every calibrated sequence with a camera folder <SEQ><i> here.
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(p.parent_path() / "calibration"))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    for (const std::string& name : names) {
      bool present = false;
      for (const auto& entry : fs::directory_iterator(p)) {
        const std::string folder = entry.path().filename().string();
        present = present || (folder.size() > name.size() && folder.rfind(name, 0) == 0 &&
                              std::all_of(folder.begin() + name.size(), folder.end(),
                                          [](char c) { return c >= '0' && c <= '9'; }));
      }
      if (!present) continue;
      sequences_.push_back(ReadHo3dSequence(p.string(), name));
      sequences_.back().prefix = name + "/";
    }
  }
  if (sequences_.empty()) {
    throw InputError(path, "input.path",
                     "<HO3D root>/<split>/<SEQ> of a sequence with <root>/calibration/"
                     "<SEQ>, or a split folder holding such sequences' camera folders",
                     fs::exists(p) ? "no calibrated sequence" : "not found");
  }
  for (size_t s = 0; s < sequences_.size(); ++s) {
    Ho3dSequence& seq = sequences_[s];
    if (cameras) {
      Rig replaced;
      for (const RigCamera& camera : seq.rig.cameras())
        replaced.Add(cameras->Find(camera.name));  // InputError lists the known names
      seq.rig = replaced;
    }
    by_prefix_[seq.prefix] = s;
  }
}

std::vector<std::string> Ho3dFrameSource::FrameIds() const {
  std::vector<std::string> ids;
  for (const Ho3dSequence& seq : sequences_) {
    for (const std::string& fid : seq.frames) ids.push_back(seq.prefix + fid);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::string Ho3dFrameSource::Describe() const {
  size_t frames = 0;
  for (const Ho3dSequence& seq : sequences_) frames += seq.frames.size();
  return "HO3D v3 " + path_ + " (" + std::to_string(sequences_.size()) + " sequence" +
         (sequences_.size() == 1 ? "" : "s") + ", " +
         std::to_string(sequences_.front().rig.size()) + " cameras, " +
         std::to_string(frames) +
         " frames, right hand, 2D keypoints: none, hand and object masks: seg/<fid>.png "
         "where present, ground truth: meta handJoints3D where present)";
}

FrameInput Ho3dFrameSource::Load(const std::string& id) const {
  const size_t slash = id.rfind('/');
  const std::string prefix = slash == std::string::npos ? "" : id.substr(0, slash + 1);
  const std::string fid = id.substr(prefix.size());
  const auto it = by_prefix_.find(prefix);
  if (it == by_prefix_.end() ||
      !std::binary_search(sequences_[it->second].frames.begin(),
                          sequences_[it->second].frames.end(), fid)) {
    throw InputError(path_, "frame id",
                     sequences_.size() == 1 ? "a frame of the sequence's rgb folders"
                                            : "<SEQ>/<fid> of a sequence",
                     "'" + id + "'");
  }
  const Ho3dSequence& seq = sequences_[it->second];
  FrameInput frame;
  frame.id = id;
  frame.rig = seq.rig;
  for (size_t v = 0; v < seq.rig.size(); ++v) {
    const std::string image = ImageFile(seq.camera_dirs[v], fid);
    if (image.empty()) {
      throw InputError((fs::path(seq.camera_dirs[v]) / "rgb" / (fid + ".jpg")).string(),
                       "rgb/<fid>.jpg",
                       "camera " + seq.rig[v].name + "'s image of frame " + fid +
                           " (another camera has one)",
                       "missing");
    }
    frame.image_paths.push_back(image);
    const std::string seg = SegmentationFile(seq.camera_dirs[v], fid);
    frame.masks.emplace_back();
    frame.object_masks.emplace_back();
    if (!seg.empty()) {
      ReadHo3dSegmentation(seg, seq.rig[v].camera, &frame.masks.back(),
                           &frame.object_masks.back());
    }
  }
  const auto empty = [](const MaskImage& m) { return m.size() == 0; };
  if (std::all_of(frame.masks.begin(), frame.masks.end(), empty)) {
    frame.masks.clear();  // no segmentation in any view
    frame.object_masks.clear();
  }
  for (size_t v = 0; v < seq.rig.size() && !frame.ground_truth; ++v) {
    const std::optional<Points3d> in_camera =
        JointsInCamera(fs::path(seq.camera_dirs[v]) / "meta" / (fid + ".pkl"));
    if (!in_camera) continue;
    FrameGroundTruth truth;
    truth.keypoints = TransformPoints(seq.rig[v].cam_from_world.Inverse(), *in_camera);
    frame.ground_truth = truth;
  }
  return frame;
}

}  // namespace handlabel
