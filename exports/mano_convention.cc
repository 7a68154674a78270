#include "exports/mano_convention.h"

#include "core/errors.h"

namespace handlabel {

std::string ToString(ManoConvention convention) {
  switch (convention) {
    case ManoConvention::kSmplx:
      return "smplx";
    case ManoConvention::kManopth:
      return "manopth";
    case ManoConvention::kManotorch:
      return "manotorch";
  }
  return "?";
}

ManoConvention ParseManoConvention(const std::string& text, const std::string& source) {
  for (ManoConvention c :
       {ManoConvention::kSmplx, ManoConvention::kManopth, ManoConvention::kManotorch}) {
    if (text == ToString(c)) return c;
  }
  throw InputError(source, "mano convention", "smplx | manopth | manotorch",
                   "'" + text + "'");
}

bool DefaultFlatHandMean(ManoConvention convention) {
  // smplx.MANO(flat_hand_mean=False), manopth's and manotorch's
  // ManoLayer(flat_hand_mean=True).
  return convention != ManoConvention::kSmplx;
}

Eigen::Matrix<double, kNumPoseParams, 1> LayerHandPose(const HandParams& label_params,
                                                       const HandModel& model,
                                                       bool flat_hand_mean) {
  if (flat_hand_mean) return label_params.hand_pose;
  if (model.pose_mean.size() != kNumPoseParams) {
    throw InputError(
        model.name, "hands_mean",
        "45 values (the layer adds them; or export with flat_hand_mean true)",
        std::to_string(model.pose_mean.size()) + " values");
  }
  return label_params.hand_pose - model.pose_mean;
}

}  // namespace handlabel
