#pragma once
// A label's MANO parameters as the layers users load them with expect them
// (docs/exports.md, "What a label's mano fields mean"). A label's `hand_pose` is the
// full rotation of each of the 15 finger joints: MANO's hands_mean is already in it.
// A layer built with flat_hand_mean = false adds hands_mean itself, so it must be given
// hand_pose - hands_mean; with flat_hand_mean = true, hand_pose as it is.
//   smplx    smplx.MANO(use_pca=False, flat_hand_mean=...)(global_orient, hand_pose,
//            betas, transl): default flat_hand_mean False; vertices and 16 joints in
//            metres, joints in MANO's native order, no fingertips
//   manopth  manopth.ManoLayer(use_pca=False, flat_hand_mean=...)(pose_coeffs (48) =
//            [global_orient, hand_pose], betas, trans): default flat_hand_mean True;
//            vertices and 21 joints (SNAP order, manopth's fingertips) in millimetres
//   manotorch manotorch.ManoLayer(rot_mode="axisang", use_pca=False, center_idx=None,
//            flat_hand_mean=...)(pose_coeffs (48), betas): default flat_hand_mean True;
//            manopth's skinning and joints but in metres and without a translation
//            argument: add transl to its verts and joints
// global_orient, betas and transl are the same for all three. Proven against NumPy
// re-implementations of the layers (tests/apps/mano_layers.py, run by
// tests/apps/export_command_test.cc).

#include <optional>
#include <string>

#include "hand/hand_lbs.h"
#include "hand/hand_model.h"

namespace handlabel {

enum class ManoConvention { kSmplx, kManopth, kManotorch };

std::string ToString(ManoConvention convention);  // "smplx" | "manopth" | "manotorch"
// Throws InputError naming `source` for another name.
ManoConvention ParseManoConvention(const std::string& text, const std::string& source);
// The flat_hand_mean a layer is built with when not told: smplx false, manopth and
// manotorch true.
bool DefaultFlatHandMean(ManoConvention convention);

// How a label's parameters are handed to a layer.
struct ManoLayerSetting {
  ManoConvention convention = ManoConvention::kSmplx;
  bool flat_hand_mean = false;  // the layer's flat_hand_mean
};

// The hand_pose to give a layer built with `flat_hand_mean`: the label's hand_pose,
// minus the model's hands_mean when the layer adds it. Throws InputError naming the
// model when it has no hands_mean but one is needed.
Eigen::Matrix<double, kNumPoseParams, 1> LayerHandPose(const HandParams& label_params,
                                                       const HandModel& model,
                                                       bool flat_hand_mean);

}  // namespace handlabel
