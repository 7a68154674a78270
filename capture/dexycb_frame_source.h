#pragma once
// The labeling job's frame source for the DexYCB layout (input.format: dexycb), read in
// place (docs/labeling-jobs.md, ../shared/datasets.md):
//   input.path  one sequence folder <root>/<subject>/<sequence> (it holds meta.yml):
//               frame ids 000000, 000001, ...; or a subject folder or the DexYCB root:
//               every sequence below it, ids <subject>/<sequence>/000000 (all of them
//               must show the same hand: one job fits one hand model)
//   meta.yml    serials (the cameras, in this order), num_frames, mano_sides, extrinsics
//   images      <sequence>/<serial>/color_%06d.jpg
//   cameras     <root>/calibration (cameras/dataset_calib.h: intrinsics per serial,
//               extrinsics_<id>; world = DexYCB's common frame), or cameras.file
//               matched by serial
//   2D keypoints  <serial>/labels_%06d.npz joint_2d [1,21,2] (SNAP order, pixels; all
//               -1 = no hand in that view, one (-1, -1) keypoint = unlabelled:
//               confidence 0) when the sequence has labels files
//   masks       the labels' seg (0 background, 255 hand, 1..254 YCB object id): the
//               hand pixels are the view's hand mask (evidence.masks: files), the
//               object pixels its object mask (evidence.object_masks: files), in memory
//   ground truth  joint_3d [1,21,3] (metres, camera frame) of the first view with a hand,
//               moved into the rig's world: keypoints only. Vertices and MANO
//               parameters (pose_m with the subject's betas) need the user's MANO model
//               and are not read.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "geometry/rig.h"

namespace handlabel {

struct DexYcbSequence {
  std::string dir;     // the sequence folder
  std::string prefix;  // "" (one sequence) or "<subject>/<sequence>/" before frame ids
  Rig rig;             // serial order of meta.yml
  // Per camera, where its image size comes from, for messages: "its intrinsics file
  // <path>" (the size is in the file's name) or "cameras.file".
  std::vector<std::string> size_origins;
  int num_frames = 0;
  HandSide side = HandSide::kRight;
  bool has_labels = false;  // labels_%06d.npz next to the images
};

// Reads <dir>/meta.yml and the calibration it names; checks that every serial's folder
// exists. Throws InputError naming meta.yml (or the calibration file) and the field.
DexYcbSequence ReadDexYcbSequence(const std::string& dir);

class DexYcbFrameSource : public FrameSource {
 public:
  // `path`: a sequence, subject or root folder (see above). `cameras`: cameras.file,
  // replacing every sequence's calibration (matched by serial).
  explicit DexYcbFrameSource(const std::string& path,
                             const std::optional<Rig>& cameras = std::nullopt);
  std::vector<std::string> FrameIds() const override;
  FrameInput Load(const std::string& id) const override;
  std::string Describe() const override;
  std::string KeypointsSource() const override;
  std::optional<HandSide> side() const override;
  const std::vector<DexYcbSequence>& sequences() const { return sequences_; }

 private:
  std::string path_;
  std::vector<DexYcbSequence> sequences_;    // sorted by folder
  std::map<std::string, size_t> by_prefix_;  // DexYcbSequence::prefix -> index
};

}  // namespace handlabel
