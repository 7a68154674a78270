#pragma once
// The labeling job's frame source for OakInk-Image (input.format: oakink), read in
// place (docs/labeling-jobs.md, ../shared/datasets.md; the layout oikit reads):
//   input.path  OakInk's image folder (anno/, stream_release_v2/), or the root holding
//               image/
//   frames      every <seq>__<ts>__<sbj>__<frame> group of anno/general_info/*.pkl
//               (one pickle per camera: <group>__<cam>.pkl); the frame id is the group
//   cameras     per frame from its pickles' cam_intr / cam_extr (cameras/dataset_calib.h,
//               PINHOLE 848x480, world = OakInk's world), named <cam>, sorted by name;
//               or cameras.file matched by name
//   images      stream_release_v2/<seq>/<ts>/<stream>_<frame>.png, where <stream> is
//               OakInk's colour stream of camera index <cam> (0 north_east_color,
//               1 south_east_color, 2 north_west_color, 3 south_west_color), or <cam>
//               itself when it is not an index
//   ground truth  anno/hand_j/<group>__<cam>.pkl (21 x 3, SNAP order) and
//               anno/hand_v/<group>__<cam>.pkl (vertices) of the first camera that has
//               them, from that camera's frame into the world
// No 2D keypoint files and no masks. OakInk-Image shows right hands.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "geometry/rig.h"

namespace handlabel {

class OakInkFrameSource : public FrameSource {
 public:
  // Lists anno/general_info. Throws InputError naming the folder or a misnamed file.
  explicit OakInkFrameSource(const std::string& path,
                             const std::optional<Rig>& cameras = std::nullopt);
  std::vector<std::string> FrameIds() const override;
  FrameInput Load(const std::string& id) const override;
  std::string Describe() const override;
  std::optional<HandSide> side() const override { return HandSide::kRight; }
  const std::string& image_dir() const { return image_dir_; }

 private:
  std::string path_;
  std::string image_dir_;  // OakInk's image/ folder
  std::optional<Rig> cameras_;
  std::map<std::string, std::vector<std::string>> cams_;  // group -> sorted <cam>s
};

// OakInk's colour stream name of camera `cam` ("0" -> "north_east_color", ...), or
// `cam` itself when it is not an index 0-3.
std::string OakInkStreamName(const std::string& cam);

}  // namespace handlabel
