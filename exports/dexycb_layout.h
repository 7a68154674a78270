#pragma once
// A label series in DexYCB's layout (docs/exports.md, "--format dexycb"), readable by
// dex-ycb-toolkit's loaders and by our in-place reader (capture/dexycb_frame_source.h):
//   <out>/calibration/intrinsics/<camera>_<W>x<H>.yml   color: fx, fy, ppx, ppy
//   <out>/calibration/extrinsics_handlabel/extrinsics.yml  camera -> world 3x4, master
//   <out>/calibration/mano_handlabel/mano.yml           betas (the first label's)
//   <out>/handlabel/<sequence>/meta.yml                  serials, num_frames, sides, ...
//   <out>/handlabel/<sequence>/<camera>/color_%06d.jpg  the capture's image (link/copy)
//   <out>/handlabel/<sequence>/<camera>/labels_%06d.npz per camera: pose_m [1,51]
//        (axis-angle root + 45 PCA coefficients of manopth's ncomps=45,
//        flat_hand_mean=False layer + trans, camera frame), joint_3d [1,21,3] (metres,
//        camera frame, SNAP), joint_2d [1,21,2] (pixels; (-1,-1) behind the camera),
//        pose_y [0,3,4] (no objects), mano_betas [1,10] (this frame's betas)
// Frame k is the k-th label in frame order; meta.yml's handlabel_frames lists the ids.

#include <string>

#include "exports/dataset_frames.h"
#include "hand/hand_model.h"

namespace handlabel {

// Returns one line saying what was written. Throws InputError naming the label file,
// the camera or the hand model that the layout cannot hold (a camera with distortion,
// a label without parameters, a model without 45 pose PCA components).
std::string WriteDexYcbLayout(const LabelSeries& series, const HandModel& model,
                              const SeriesCapture& capture,
                              const DatasetLayoutOptions& options);

}  // namespace handlabel
