#pragma once
// A label series in HO3D v3's multi-camera layout (docs/exports.md, "--format ho3d"),
// readable by the HO3D repository's loaders and by our in-place reader
// (capture/ho3d_frame_source.h):
//   <out>/calibration/HANDLABEL/calibration/cam_orders.txt   0 1 ... n-1
//   <out>/calibration/HANDLABEL/calibration/trans_<i>.txt    4x4 camera -> world
//   <out>/calibration/HANDLABEL/calibration/cam_<i>_intrinsics.txt  fx:, fy:, ppx:, ppy:
//   <out>/train/HANDLABEL<i>/rgb/<fid>.jpg|png               the capture's image
//   <out>/train/HANDLABEL<i>/meta/<fid>.pkl                  per camera, OpenGL camera
//        axes: handPose (48: root + 15 joints, axis-angle, hands_mean included, as
//        HO3D's flat_hand_mean=True MANO takes it), handTrans (3), handBeta (10),
//        handJoints3D (21 x 3, MANO joint order + fingertips), camMat (3 x 3)
//   <out>/calibration/HANDLABEL/handlabel.json               frame ids, camera names
// fid = the label's index in frame order, 4 digits. Right hands, 640 x 480 cameras
// without distortion (HO3D's calibration files carry no size: its tools assume it).

#include <string>

#include "exports/dataset_frames.h"

namespace handlabel {

// Returns one line saying what was written. Throws InputError naming the label file or
// camera the layout cannot hold.
std::string WriteHo3dLayout(const LabelSeries& series, const SeriesCapture& capture,
                            const DatasetLayoutOptions& options);

}  // namespace handlabel
