#include "exports/dataset_frames.h"

#include <Eigen/Geometry>
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "core/errors.h"

namespace handlabel {

namespace fs = std::filesystem;

namespace {

// The same cameras (names, intrinsics, poses) as `first`.
bool SameRig(const Rig& first, const Rig& other) {
  if (first.size() != other.size()) return false;
  for (size_t c = 0; c < first.size(); ++c) {
    const RigCamera& a = first[c];
    const RigCamera& b = other[c];
    if (a.name != b.name || a.camera.model() != b.camera.model() ||
        a.camera.params() != b.camera.params() || a.camera.width() != b.camera.width() ||
        a.camera.height() != b.camera.height() ||
        RotationAngleBetween(a.cam_from_world, b.cam_from_world) > 1e-12 ||
        (a.cam_from_world.translation - b.cam_from_world.translation).norm() > 1e-12) {
      return false;
    }
  }
  return true;
}

}  // namespace

SeriesCapture ReadSeriesCapture(const LabelSeries& series, const FrameSource& source) {
  SeriesCapture capture;
  capture.described = source.Describe();
  for (const LabelRecord& label : series.labels) {
    FrameInput frame;
    try {
      frame = source.Load(label.frame);
    } catch (const InputError& e) {
      throw InputError(series.FileOf(label.frame), "frame",
                       "a frame of the job's capture " + source.Describe(), e.what());
    }
    if (capture.images.empty()) {
      capture.rig = frame.rig;
    } else if (!SameRig(capture.rig, frame.rig)) {
      throw InputError(series.FileOf(label.frame), "frame",
                       "the cameras of frame " + series.labels.front().frame +
                           " (a dataset sequence has one calibration)",
                       "other cameras in the capture");
    }
    capture.images.push_back(frame.image_paths);
  }
  return capture;
}

void RequireParameters(const LabelSeries& series, const std::string& format) {
  for (const LabelRecord& label : series.labels) {
    if (!label.params) {
      throw InputError(series.FileOf(label.frame), "mano",
                       "MANO parameters (the " + format +
                           " export writes pose parameters; network-path labels have "
                           "none)",
                       "null");
    }
  }
}

HandParams ParamsInFrame(const LabelRecord& label, const Eigen::Matrix3d& rotation,
                         const Eigen::Vector3d& translation) {
  HandParams out = *label.params;
  const Eigen::Vector3d& go = label.params->global_orient;
  const Eigen::Matrix3d root =
      go.norm() > 0 ? Eigen::AngleAxisd(go.norm(), go.normalized()).toRotationMatrix()
                    : Eigen::Matrix3d::Identity();
  const Eigen::AngleAxisd turned(rotation * root);
  out.global_orient = turned.angle() * turned.axis();
  // posed = root (x - J0) + J0 + t; in the frame: rotation (J0 + t) + translation is
  // where the wrist goes, so t' = that - J0.
  const Eigen::Vector3d rest_wrist =
      label.mesh.keypoints.row(0).transpose() - label.params->transl;
  out.transl = rotation * (rest_wrist + label.params->transl) + translation - rest_wrist;
  return out;
}

Eigen::Vector4d PinholeIntrinsics(const RigCamera& camera, const std::string& format) {
  if (camera.camera.HasDistortion()) {
    throw InputError("camera " + camera.name, "model",
                     "no distortion (" + format +
                         "'s intrinsics hold fx, fy, ppx, ppy only; undistort the "
                         "capture's images first)",
                     "a camera with distortion");
  }
  return {camera.camera.fx(), camera.camera.fy(), camera.camera.cx(), camera.camera.cy()};
}

std::string SeriesName(const LabelSeries& series) {
  fs::path folder = fs::absolute(series.labels_dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();
  if (folder.filename() == "labels") folder = folder.parent_path();
  std::string name = folder.filename().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  return name.empty() ? "labels" : name;
}

std::string ToString(ImagePlacement placement) {
  return placement == ImagePlacement::kLink ? "link" : "copy";
}

ImagePlacement ParseImagePlacement(const std::string& text, const std::string& source) {
  if (text == "link") return ImagePlacement::kLink;
  if (text == "copy") return ImagePlacement::kCopy;
  throw InputError(source, "images", "link | copy", "'" + text + "'");
}

void PlaceImage(const std::string& image, const std::string& path,
                ImagePlacement placement) {
  const fs::path target = fs::absolute(image);
  if (!fs::is_regular_file(target)) {
    throw InputError(image, "(image)", "the capture's image file", "not found");
  }
  fs::create_directories(fs::path(path).parent_path());
  std::error_code ignored;
  fs::remove(path, ignored);  // replace an earlier export's file or link
  if (placement == ImagePlacement::kLink) {
    fs::create_symlink(target, path);
  } else {
    fs::copy_file(target, path);
  }
}

std::string ZeroPadded(int64_t n, int digits) {
  char text[32];
  std::snprintf(text, sizeof(text), "%0*lld", digits, static_cast<long long>(n));
  return text;
}

}  // namespace handlabel
