#pragma once
// What the per-frame dataset layouts (DexYCB, HO3D; docs/exports.md) share: the
// capture's rig and image files behind a label series, a label's MANO parameters
// moved into a camera's frame, and the images placed in the layout.

#include <memory>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "exports/label_series.h"

namespace handlabel {

// The rig and each label's image files (one per camera), from the job's capture. The
// datasets hold one calibration per sequence, so the rig must be the same for every
// frame.
struct SeriesCapture {
  Rig rig;
  std::vector<std::vector<std::string>> images;  // [label][camera]
  std::string described;                         // FrameSource::Describe()
};

// Throws InputError naming the label file of a frame the capture cannot give, or whose
// rig differs from the first frame's.
SeriesCapture ReadSeriesCapture(const LabelSeries& series, const FrameSource& source);

// Throws InputError naming the label file of the first label without MANO parameters
// (network-path labels carry none): `format` names the export for the message.
void RequireParameters(const LabelSeries& series, const std::string& format);

// A label's parameters for the same hand in another frame: the model posed with the
// result is `frame_from_world` applied to the label's hand (`rotation` proper, det +1).
// Only global_orient and transl change: the hand turns about its rest wrist J_0(betas),
// which the label gives as keypoints_3d[0] - transl.
HandParams ParamsInFrame(const LabelRecord& label, const Eigen::Matrix3d& rotation,
                         const Eigen::Vector3d& translation);

// fx, fy, cx, cy of a camera without distortion. Throws InputError naming the camera
// for one with distortion: `format`'s intrinsics have none.
Eigen::Vector4d PinholeIntrinsics(const RigCamera& camera, const std::string& format);

// A name for the exported sequence: the job's output folder (the labels folder's
// parent), characters other than letters, digits, '-' and '_' replaced by '_'.
std::string SeriesName(const LabelSeries& series);

enum class ImagePlacement { kLink, kCopy };
std::string ToString(ImagePlacement placement);  // "link" | "copy"
// Throws InputError naming `source` for another name.
ImagePlacement ParseImagePlacement(const std::string& text, const std::string& source);

struct DatasetLayoutOptions {
  std::string out;  // the dataset root to write
  ImagePlacement images = ImagePlacement::kLink;
};

// Puts `image` at `path` (folders made; an existing file replaced): a symbolic link to
// its absolute path, or a copy of its bytes. The bytes are never re-encoded: readers
// (OpenCV's, ours) read PNG or JPEG by content, whatever the name says.
void PlaceImage(const std::string& image, const std::string& path,
                ImagePlacement placement);

// "%0<digits>d" of n.
std::string ZeroPadded(int64_t n, int digits);

}  // namespace handlabel
