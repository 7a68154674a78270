#include "capture/dexycb_frame_source.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cameras/dataset_calib.h"
#include "core/errors.h"
#include "core/text.h"
#include "formats/npz.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

std::string FrameNumber(int frame) {
  char text[16];
  std::snprintf(text, sizeof(text), "%06d", frame);
  return text;
}

// <sequence>/<serial>/<kind>_%06d<extension>
std::string ViewFile(const DexYcbSequence& seq, size_t view, const std::string& kind,
                     int frame) {
  const char* extension = kind == "color" ? ".jpg" : ".npz";
  return (fs::path(seq.dir) / seq.rig[view].name /
          (std::string(kind) + "_" + FrameNumber(frame) + extension))
      .string();
}

// "what" of a YAML node, for messages.
std::string Shown(const YAML::Node& node) {
  if (!node) return "missing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  return node.IsSequence() ? "a list" : "a map";
}

const NdArray& FindArray(const NamedArrays& arrays, const std::string& name,
                         const std::vector<int64_t>& shape, const std::string& file) {
  for (const auto& [key, array] : arrays) {
    if (key != name) continue;
    if (array.shape != shape || !IsNumeric(array.dtype)) {
      std::vector<std::string> sizes;
      for (const int64_t size : shape) sizes.push_back(std::to_string(size));
      throw InputError(file, name, "a numeric array of shape (" + Join(sizes) + ")",
                       array.ShapeString());
    }
    return array;
  }
  throw InputError(file, name, "an array (DexYCB labels file)", "missing");
}

// DexYCB writes -1 everywhere for a view without the hand.
bool HasHand(const std::vector<double>& values) {
  return std::any_of(values.begin(), values.end(), [](double v) { return v != -1.0; });
}

// The labels' seg (H x W, uint8: 0 background, 255 hand, 1..254 the YCB id of the
// object at that pixel) as the view's hand mask and object mask; both empty when the
// file has no seg.
// `size_origin` says where the camera's size comes from (a DexYCB intrinsics file of
// another size than the images is otherwise found only here, in every frame).
void AddSegmentation(const NamedArrays& arrays, const std::string& file,
                     const Camera& camera, const std::string& size_origin,
                     FrameInput* frame) {
  const NdArray* seg = nullptr;
  for (const auto& [key, array] : arrays) {
    if (key == "seg") seg = &array;
  }
  MaskImage hand, objects;
  if (seg) {
    if (seg->ndim() != 2 || seg->dtype != DType::kUInt8) {
      throw InputError(file, "seg",
                       "an H x W uint8 array (0 background, 255 hand, "
                       "1..254 object ids)",
                       seg->ShapeString() + " " + DTypeName(seg->dtype));
    }
    if (seg->shape[0] != camera.height() || seg->shape[1] != camera.width()) {
      throw InputError(file, "seg",
                       "the camera's size " + std::to_string(camera.height()) + " x " +
                           std::to_string(camera.width()) + " (from " + size_origin + ")",
                       seg->ShapeString());
    }
    hand.resize(seg->shape[0], seg->shape[1]);
    objects.resize(seg->shape[0], seg->shape[1]);
    const uint8_t* v = seg->data.data();
    for (Eigen::Index i = 0; i < hand.size(); ++i) {
      hand.data()[i] = v[i] == 255 ? 255 : 0;
      objects.data()[i] = v[i] != 0 && v[i] != 255 ? 255 : 0;
    }
  }
  frame->masks.push_back(std::move(hand));
  frame->object_masks.push_back(std::move(objects));
}

}  // namespace

DexYcbSequence ReadDexYcbSequence(const std::string& dir) {
  const fs::path meta_path = fs::path(dir) / "meta.yml";
  const std::string m = meta_path.string();
  if (!fs::is_regular_file(meta_path)) {
    throw InputError(dir, "meta.yml", "a DexYCB sequence folder holding meta.yml",
                     "not found");
  }
  YAML::Node meta;
  try {
    meta = YAML::LoadFile(m);
  } catch (const YAML::Exception& e) {
    throw InputError(m, "(YAML syntax)", "valid YAML", e.what());
  }
  if (!meta.IsMap()) throw InputError(m, "(top level)", "a map", Shown(meta));
  DexYcbSequence seq;
  seq.dir = dir;
  const YAML::Node serials = meta["serials"];
  if (!serials || !serials.IsSequence() || serials.size() == 0) {
    throw InputError(m, "serials", "a non-empty list of camera serials", Shown(serials));
  }
  const YAML::Node frames = meta["num_frames"];
  try {
    seq.num_frames = frames && frames.IsScalar() ? frames.as<int>() : 0;
  } catch (const YAML::Exception&) {
    seq.num_frames = 0;
  }
  if (seq.num_frames < 1)
    throw InputError(m, "num_frames", "an integer >= 1", Shown(frames));
  const YAML::Node sides = meta["mano_sides"];
  const bool listed = sides && sides.IsSequence() && sides.size() > 0;
  const std::optional<HandSide> side =
      listed && sides[0].IsScalar() ? HandSideFromName(sides[0].Scalar()) : std::nullopt;
  if (!side) {
    throw InputError(m, "mano_sides", "a list whose first entry is right or left",
                     listed ? Shown(sides[0]) : Shown(sides));
  }
  seq.side = *side;
  RigFileInfo info;
  seq.rig = ReadDatasetRig("dexycb", m, &info);  // serials + <root>/calibration
  for (const std::string& file : info.intrinsics_files) {
    seq.size_origins.push_back("its intrinsics file " + file);
  }
  for (const RigCamera& camera : seq.rig.cameras()) {
    if (!fs::is_directory(fs::path(dir) / camera.name)) {
      throw InputError(m, "serials",
                       "a camera folder " + (fs::path(dir) / camera.name).string() +
                           " with color_%06d.jpg per frame",
                       "no folder for serial " + camera.name);
    }
  }
  seq.has_labels = fs::exists(ViewFile(seq, 0, "labels", 0));
  return seq;
}

DexYcbFrameSource::DexYcbFrameSource(const std::string& path,
                                     const std::optional<Rig>& cameras)
    : path_(path) {
  std::vector<fs::path> dirs;
  if (fs::exists(fs::path(path) / "meta.yml")) {
    dirs.push_back(path);
  } else if (fs::is_directory(path)) {
    // A subject folder (sequences one level down) or the root (two levels down).
    for (const auto& a : fs::directory_iterator(path)) {
      if (!a.is_directory()) continue;
      if (fs::exists(a.path() / "meta.yml")) {
        dirs.push_back(a.path());
        continue;
      }
      for (const auto& b : fs::directory_iterator(a.path())) {
        if (b.is_directory() && fs::exists(b.path() / "meta.yml"))
          dirs.push_back(b.path());
      }
    }
  }
  if (dirs.empty()) {
    throw InputError(
        path, "input.path",
        "a DexYCB sequence folder (with meta.yml), subject folder or root",
        fs::exists(path) ? "no meta.yml in it or two levels below" : "not found");
  }
  std::sort(dirs.begin(), dirs.end());
  for (const fs::path& dir : dirs) {
    DexYcbSequence seq = ReadDexYcbSequence(dir.string());
    if (dirs.size() > 1) {
      seq.prefix =
          dir.parent_path().filename().string() + "/" + dir.filename().string() + "/";
    }
    if (cameras) {
      Rig replaced;
      for (const RigCamera& camera : seq.rig.cameras()) {
        replaced.Add(cameras->Find(camera.name));  // InputError lists the known names
      }
      seq.rig = replaced;
      seq.size_origins.assign(seq.rig.size(), "cameras.file");
    }
    if (!sequences_.empty() && seq.side != sequences_.front().side) {
      throw InputError((dir / "meta.yml").string(), "mano_sides",
                       "the same hand as " + sequences_.front().dir +
                           " (one job labels one hand side; split the job)",
                       HandSideName(seq.side));
    }
    by_prefix_[seq.prefix] = sequences_.size();
    sequences_.push_back(std::move(seq));
  }
}

std::vector<std::string> DexYcbFrameSource::FrameIds() const {
  std::vector<std::string> ids;
  for (const DexYcbSequence& seq : sequences_) {
    for (int f = 0; f < seq.num_frames; ++f) ids.push_back(seq.prefix + FrameNumber(f));
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::optional<HandSide> DexYcbFrameSource::side() const {
  return sequences_.front().side;
}

std::string DexYcbFrameSource::Describe() const {
  size_t frames = 0;
  bool labels = true;
  for (const DexYcbSequence& seq : sequences_) {
    frames += static_cast<size_t>(seq.num_frames);
    labels = labels && seq.has_labels;
  }
  return "DexYCB " + path_ + " (" + std::to_string(sequences_.size()) + " sequence" +
         (sequences_.size() == 1 ? "" : "s") + ", " +
         std::to_string(sequences_.front().rig.size()) + " cameras, " +
         std::to_string(frames) + " frames, " + HandSideName(sequences_.front().side) +
         " hand, 2D keypoints and ground truth keypoints: " +
         (labels ? "labels_*.npz" : "none") +
         ", hand and object masks: " + (labels ? "labels_*.npz seg" : "none") + ")";
}

std::string DexYcbFrameSource::KeypointsSource() const {
  for (const DexYcbSequence& seq : sequences_) {
    if (!seq.has_labels) return "";
  }
  return "DexYCB labels_*.npz joint_2d";
}

FrameInput DexYcbFrameSource::Load(const std::string& id) const {
  // <prefix><6 digits>
  const size_t cut = id.size() >= 6 ? id.size() - 6 : 0;
  const auto it = by_prefix_.find(id.substr(0, cut));
  const std::string digits = id.substr(cut);
  const bool numeric =
      digits.size() == 6 && std::all_of(digits.begin(), digits.end(),
                                        [](char c) { return c >= '0' && c <= '9'; });
  const int f = numeric ? std::stoi(digits) : -1;
  if (it == by_prefix_.end() || f < 0 || f >= sequences_[it->second].num_frames) {
    throw InputError(
        path_, "frame id",
        sequences_.size() == 1
            ? "a frame number 000000.." + FrameNumber(sequences_[0].num_frames - 1)
            : "<subject>/<sequence>/<6-digit frame> of a sequence",
        "'" + id + "'");
  }
  const DexYcbSequence& seq = sequences_[it->second];
  FrameInput frame;
  frame.id = id;
  frame.rig = seq.rig;
  for (size_t v = 0; v < seq.rig.size(); ++v) {
    const std::string image = ViewFile(seq, v, "color", f);
    if (!fs::is_regular_file(image)) {
      throw InputError(image, "color_%06d.jpg",
                       "camera " + seq.rig[v].name + "'s image of frame " +
                           FrameNumber(f) + " (meta.yml num_frames is " +
                           std::to_string(seq.num_frames) + ")",
                       "missing");
    }
    frame.image_paths.push_back(image);
  }
  if (!seq.has_labels) return frame;  // no 2D, no masks, no ground truth
  for (size_t v = 0; v < seq.rig.size(); ++v) {
    const std::string file = ViewFile(seq, v, "labels", f);
    if (!fs::is_regular_file(file)) {
      throw InputError(file, "labels_%06d.npz",
                       "camera " + seq.rig[v].name + "'s labels of frame " +
                           FrameNumber(f) + " (the sequence has labels files)",
                       "missing");
    }
    const NamedArrays arrays = ReadNpzFile(file);
    const std::vector<double> uv =
        FindArray(arrays, "joint_2d", {1, kNumHandKeypoints, 2}, file).ToDoubles();
    const std::vector<double> xyz =
        FindArray(arrays, "joint_3d", {1, kNumHandKeypoints, 3}, file).ToDoubles();
    std::optional<Keypoints2d> view;
    if (HasHand(uv)) {
      view.emplace();
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        // (-1, -1): the toolkit's "unlabelled" keypoint, not an observation.
        const bool known = std::isfinite(uv[2 * k]) && std::isfinite(uv[2 * k + 1]) &&
                           !(uv[2 * k] == -1.0 && uv[2 * k + 1] == -1.0);
        if (known) view->uv_px.row(k) << uv[2 * k], uv[2 * k + 1];
        view->confidence(k) = known ? 1.0 : 0.0;
      }
    }
    frame.keypoints_2d.push_back(view);
    AddSegmentation(arrays, file, seq.rig[v].camera, seq.size_origins[v], &frame);
    if (!frame.ground_truth && HasHand(xyz)) {
      const Eigen::Map<const Points3d> in_camera(xyz.data(), kNumHandKeypoints, 3);
      FrameGroundTruth truth;
      truth.keypoints = TransformPoints(seq.rig[v].cam_from_world.Inverse(), in_camera);
      frame.ground_truth = truth;
    }
  }
  const auto empty = [](const MaskImage& m) { return m.size() == 0; };
  if (std::all_of(frame.masks.begin(), frame.masks.end(), empty)) {
    frame.masks.clear();  // no seg in any view: no mask evidence at all
    frame.object_masks.clear();
  }
  return frame;
}

}  // namespace handlabel
