#pragma once
// A label series as arrays over time, for analysis (docs/exports.md):
//   npz  frames (N,) str, label_path (N,) str, keypoints_3d (N,21,3), joints_native
//        (N,16,3), vertices (N,V,3), all metres in the rig's world frame; has_mano
//        (N,) bool and global_orient (N,3), hand_pose (N,45), betas (N,10), transl (N,3)
//        in the layer setting's convention (NaN rows where a label has no parameters),
//        manopth adding pose_coeffs (N,48); and 0-d strings / bools saying what they
//        are: mano_convention, flat_hand_mean, hand_side, hand_model, keypoints_order,
//        units
//   csv  one row per frame: frame, path, then x, y, z of the 21 keypoints (SNAP
//        order, metres), columns named <keypoint>_<x|y|z>
// Both written atomically.

#include <string>

#include "exports/label_series.h"
#include "exports/mano_convention.h"

namespace handlabel {

// `model`: the labels' hand model, needed only when the layer adds hands_mean
// (setting.flat_hand_mean false) and some label has parameters; may be null otherwise.
void WriteKeypointsNpz(const LabelSeries& series, const ManoLayerSetting& setting,
                       const HandModel* model, const std::string& path);

void WriteKeypointsCsv(const LabelSeries& series, const std::string& path);

}  // namespace handlabel
