#pragma once
// The labeling job's frame source for HO3D v3's multi-camera sequences
// (input.format: ho3d), read in place (docs/labeling-jobs.md, ../shared/datasets.md):
//   input.path  <root>/<split>/<SEQ> (e.g. HO3D_v3/train/ABF1; the folder itself need
//               not exist): one multi-camera sequence, frame ids = HO3D's (0000, ...);
//               or <root>/<split>: every sequence of <root>/calibration with camera
//               folders in that split, ids <SEQ>/<fid>
//   cameras     <root>/calibration/<SEQ>/calibration (cameras/dataset_calib.h): cameras
//               <SEQ><i> for i in cam_orders.txt, world = the sequence's common frame;
//               or cameras.file matched by name
//   images      <root>/<split>/<SEQ><i>/rgb/<fid>.jpg (or .png): frame <fid> of every
//               camera folder is one multi-view frame; the frames are those of any
//               camera (one missing in another camera fails that frame, naming it)
//   ground truth  meta/<fid>.pkl handJoints3D (21 x 3, OpenGL camera axes, MANO joint
//               order + tips) of the first camera that has it, turned into OpenCV axes,
//               SNAP order and the rig's world: keypoints only (vertices and MANO
//               parameters need the user's MANO model and are not read)
//   masks       <SEQ><i>/seg/<fid>.png (or .jpg) where present: blue = hand (the
//               view's hand mask), green = object (its object mask), in memory
// No 2D keypoint files: HO3D has none (a label job takes them from
// evidence.detections). HO3D shows right hands only.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "geometry/rig.h"

namespace handlabel {

struct Ho3dSequence {
  std::string name;                      // SEQ, e.g. ABF1
  std::vector<std::string> camera_dirs;  // <root>/<split>/<SEQ><i>, rig order
  Rig rig;
  std::vector<std::string> frames;  // fids, sorted
  std::string prefix;               // "" (one sequence) or "<SEQ>/"
};

class Ho3dFrameSource : public FrameSource {
 public:
  // Throws InputError naming the path and what is missing.
  explicit Ho3dFrameSource(const std::string& path,
                           const std::optional<Rig>& cameras = std::nullopt);
  std::vector<std::string> FrameIds() const override;
  FrameInput Load(const std::string& id) const override;
  std::string Describe() const override;
  std::optional<HandSide> side() const override { return HandSide::kRight; }
  const std::vector<Ho3dSequence>& sequences() const { return sequences_; }

 private:
  std::string path_;
  std::vector<Ho3dSequence> sequences_;
  std::map<std::string, size_t> by_prefix_;
};

// The sequence <SEQ> of a split folder: reads its calibration and lists its frames.
Ho3dSequence ReadHo3dSequence(const std::string& split_dir, const std::string& name);

}  // namespace handlabel
